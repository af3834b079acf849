//! The pipeline as one call: source text → diagnostics and, when resolution
//! got that far, the model. Used by the CLI and by tests; never prints.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::{self, grammar};
use crate::implicit::xml::ImplicitSubdomain;
use crate::ir::{Dimension, SubdomainCells};
use crate::lower::{self, Lowered};
use crate::resolve::{self, Override};
use crate::span::SourceFile;
use crate::syntax::{self, Limits};
use std::path::Path;

#[derive(Debug, Clone, Default)]
pub struct Options {
    /// `--set NAME=VALUE` overrides, already parsed.
    pub overrides: Vec<Override>,
    pub limits: Limits,
    /// Folders besides the input's own from which data files may be read (`--allow-path`).
    pub allowed_paths: Vec<std::path::PathBuf>,
    /// Size bounds of one attribute expression (`--max-expression-nodes`, `--max-expression-depth`).
    pub expressions: crate::expr::ExprLimits,
    /// Called where a stage's large inputs have just been dropped, so the
    /// allocator can hand their memory back before the next stage allocates
    /// (the `geomc` binary passes `allocator::release_freed_memory`).
    pub release_memory: Option<fn()>,
}

/// The outcome of checking one source.
#[derive(Debug, Clone)]
pub struct Checked {
    pub source: SourceFile,
    pub diagnostics: Diagnostics,
    /// The model, when the file parsed and resolved (it may still have errors).
    pub lowered: Option<Lowered>,
    /// Subdomains whose solids are implicit (`<rfunction>`, `<level_surface>`,
    /// `<density_volume>`): polygonized by compile rather than meshed from faces.
    pub implicit: Vec<ImplicitSubdomain>,
}

impl Checked {
    pub fn is_valid(&self) -> bool {
        !self.diagnostics.has_errors()
    }
}

/// Reads and checks a file. I/O problems are returned as errors (exit code 2
/// in the CLI); everything about the content is a diagnostic.
pub fn check_file(path: &Path, options: &Options) -> std::io::Result<Checked> {
    let name = path.display().to_string();
    let metadata = std::fs::metadata(path)?;
    if metadata.len() > options.limits.max_file_size as u64 {
        let mut diagnostics = Diagnostics::default();
        diagnostics.push(
            Diagnostic::new(
                Code::FileTooLarge,
                None,
                format!(
                    "the file is {} bytes, over the limit of {} bytes",
                    metadata.len(),
                    options.limits.max_file_size
                ),
            )
            .with_help("raise the limit with --max-file-size BYTES"),
        );
        return Ok(Checked {
            source: SourceFile::new(name, ""),
            diagnostics,
            lowered: None,
            implicit: Vec::new(),
        });
    }
    let bytes = std::fs::read(path)?;
    Ok(check_bytes(name, bytes, options))
}

/// Checks raw bytes (refusing text that is not UTF-8).
pub fn check_bytes(name: String, bytes: Vec<u8>, options: &Options) -> Checked {
    match String::from_utf8(bytes) {
        Ok(text) => check_source(SourceFile::new(name, text), options),
        Err(error) => {
            let offset = error.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(error.as_bytes()).into_owned();
            let source = SourceFile::new(name, text);
            let mut diagnostics = Diagnostics::default();
            diagnostics.push(
                Diagnostic::new(
                    Code::NotUtf8,
                    crate::span::Span::new(offset, offset + 1),
                    format!("byte {offset} is not valid UTF-8"),
                )
                .with_help("save the file as UTF-8 (for example: iconv -f latin1 -t utf-8)"),
            );
            Checked {
                source,
                diagnostics,
                lowered: None,
                implicit: Vec::new(),
            }
        }
    }
}

pub fn check_source(source: SourceFile, options: &Options) -> Checked {
    let mut diags = Diagnostics::default();
    let mut implicit = Vec::new();
    let lowered = run(&source, options, &mut diags, &mut implicit);
    diags.sort();
    Checked {
        source,
        diagnostics: diags,
        lowered,
        implicit,
    }
}

fn run(
    source: &SourceFile,
    options: &Options,
    diags: &mut Diagnostics,
    implicit: &mut Vec<ImplicitSubdomain>,
) -> Option<Lowered> {
    let (mut document, extracted) = read(source, options, diags)?;
    // Each stage's input is dropped as soon as the next no longer needs it,
    // which keeps the peak memory of large files down (the parsed document
    // is gone already).
    release(options);
    // Everything later reads the resolved objects, not the document's: on large
    // files they are a fifth of the peak memory while the model is lowered, so
    // resolution takes them.
    let resolved = resolve::resolve(source, &mut document, &options.overrides, diags);
    release(options);
    // Lowering takes the subdomain definitions (dropped once lowered, before
    // the overlap check at the memory peak); only their count is read later.
    let defined_subdomains = document.subdomains.len();
    let keep_resolved = !extracted.is_empty();
    let (mut lowered, resolved) = lower::lower(
        &mut document,
        resolved,
        keep_resolved,
        diags,
        options.release_memory,
    );
    if let Some(resolved) = &resolved {
        let (subdomains, trims) = lower_implicit(source, options, &extracted, resolved, diags);
        *implicit = subdomains;
        set_trims(&mut lowered.model, trims);
    }
    if lowered.model.dimension == crate::ir::Dimension::Three {
        crate::implicit::xml::warn_area_in_3d(implicit, diags);
        // Trimmed surfaces become faces, edges and vertices (issue 9).
        let (model, map) = (&mut lowered.model, &lowered.source_map);
        lower::trimmed_topology::add(model, map, diags);
    }
    if lowered.model.dimension == crate::ir::Dimension::Two
        && (!implicit.is_empty() || !extracted.carves.is_empty())
    {
        // 2D R-function regions become model entities (issue 6), joined to
        // the kernel regions they touch or are carved from.
        let (model, map) = (&mut lowered.model, &mut lowered.source_map);
        let first_region = model.subdomains.len();
        lower::rfunction_region::add_regions(model, map, implicit, diags);
        let region_of = whole_solids(&extracted.subdomains);
        let carves = &extracted.carves;
        lower::region_interfaces::join(model, map, first_region, carves, &region_of, diags);
    }
    drop(resolved);
    release(options);
    diags.extend(crate::valid::check_topology(
        &lowered.model,
        &lowered.source_map,
    ));
    check_domain(&document, defined_subdomains, &lowered, diags);
    if !extracted.subdomains.is_empty() {
        // The implicit subdomains describe the domain.
        diags.items.retain(|d| d.code != Code::EmptySubdomainList);
    }
    if diags.has_errors() {
        // An entity left unused because something else failed is a consequence,
        // not a finding of its own.
        diags.items.retain(|d| d.code != Code::Dangling);
    }
    Some(lowered)
}

/// (solid, subdomain) for each implicit subdomain whose tree is one
/// `<solid ref>`.
fn whole_solids(subdomains: &[crate::syntax::Element]) -> Vec<(String, String)> {
    subdomains
        .iter()
        .filter_map(|s| {
            let name = s.attribute("name")?.value.trim().to_string();
            let [child] = s.children.as_slice() else {
                return None;
            };
            let solid = child.attribute("ref").filter(|_| child.name == "solid")?;
            Some((solid.value.trim().to_string(), name))
        })
        .collect()
}

/// Parses the file and reads its typed document; the parser's document is
/// dropped on return. `None` when the file did not parse or its root is not a
/// version-1 `<geometry>` (reported).
fn read<'s>(
    source: &'s SourceFile,
    options: &Options,
    diags: &mut Diagnostics,
) -> Option<(doc::Document, crate::implicit::xml::Extracted<'s>)> {
    let start = diags.items.len();
    match syntax::parse_document(source, &options.limits) {
        Ok(parsed) => match read_checked(source, &parsed, options, diags) {
            Ok(read) => return read,
            // A piece of a split file could not be read on its own: the whole
            // file is read as one below, which reports what the piece could not take.
            Err(syntax::Reparse) => diags.items.truncate(start),
        },
        Err(d) => {
            diags.push(d);
            return None;
        }
    }
    let whole = match syntax::parse_whole_document(source, &options.limits) {
        Ok(whole) => whole,
        Err(d) => {
            diags.push(d);
            return None;
        }
    };
    read_checked(source, &whole, options, diags).unwrap_or_else(|syntax::Reparse| {
        diags.push(syntax::lost_position(None));
        None
    })
}

/// The root's checks (its name and version), then [`read_document`]; `None`
/// when the root is not a version-1 `<geometry>` (reported).
#[allow(clippy::type_complexity)]
fn read_checked<'s>(
    source: &SourceFile,
    parsed: &syntax::Document<'s>,
    options: &Options,
    diags: &mut Diagnostics,
) -> Result<Option<(doc::Document, crate::implicit::xml::Extracted<'s>)>, syntax::Reparse> {
    let root = match parsed.root() {
        Ok(root) => root,
        Err(d) => {
            diags.push(d);
            return Ok(None);
        }
    };
    if root.name != grammar::GEOMETRY.name {
        diags.push(
            Diagnostic::new(
                Code::WrongRoot,
                root.name_span,
                format!(
                    "the root element is <{}>; a geomc file's root is <geometry>",
                    root.name
                ),
            )
            .with_help("wrap the content in <geometry version=\"1\"> … </geometry>"),
        );
        return Ok(None);
    }
    if let Some(version) = root.attribute("version")
        && version.value.trim() != "1"
    {
        diags.push(
            Diagnostic::new(
                Code::UnsupportedVersion,
                version.value_span,
                format!(
                    "format version \"{}\" is not supported; this geomc reads version 1",
                    version.value
                ),
            )
            .with_help("set version=\"1\""),
        );
        return Ok(None);
    }
    read_document(source, parsed, root, options, diags).map(Some)
}

/// Checks the structure of the parsed file and builds its typed document, one
/// top-level element at a time: each element is built from the parser's
/// document, checked, and dropped once its part of the typed document is made,
/// so no whole element tree is ever alive. `root` is the root without its
/// children; the root's own check reads only their [`syntax::Head`]s. Implicit
/// solids and the subdomains using them are taken out for their own path.
fn read_document<'s>(
    source: &SourceFile,
    parsed: &syntax::Document<'s>,
    root: syntax::Element<'s>,
    options: &Options,
    diags: &mut Diagnostics,
) -> Result<(doc::Document, crate::implicit::xml::Extracted<'s>), syntax::Reparse> {
    let heads = parsed.heads();
    let extractor = crate::implicit::xml::Extractor::new(&root, &heads);
    let mut builder = doc::DocumentBuilder::new(source, &root, &options.expressions);
    let subdomains = heads.iter().filter(|h| h.name == "subdomain").count();
    builder.reserve(heads.len() - subdomains, subdomains);
    let mut extracted = crate::implicit::xml::Extracted::default();
    // The root's check reports unknown elements; only known ones go deeper.
    let check_root = |found: &mut Diagnostics| {
        doc::structure::check_element_heads(&root, &heads, &grammar::GEOMETRY, found);
    };
    if let Some(runs) = parsed.runs() {
        let read = Reading {
            extractor: &extractor,
            builder: &mut builder,
            extracted: &mut extracted,
            diags,
        };
        read_runs(&runs, check_root, read)?;
        return Ok((builder.finish(), extracted));
    }
    check_root(diags);
    drop(heads);
    for element in parsed.top_level() {
        read_element(element?, &extractor, &mut builder, &mut extracted, diags);
    }
    Ok((builder.finish(), extracted))
}

/// Checks one top-level element and adds it to the document (or to what the
/// implicit path takes); [`read_runs`] does the same in two steps.
fn read_element<'s>(
    element: syntax::Element<'s>,
    extractor: &crate::implicit::xml::Extractor,
    builder: &mut doc::DocumentBuilder,
    extracted: &mut crate::implicit::xml::Extracted<'s>,
    diags: &mut Diagnostics,
) {
    if let Some(rule) = grammar::GEOMETRY.child_rule(element.name) {
        doc::structure::check(&element, rule, diags);
    }
    if let Some(element) = extractor.take(element, extracted) {
        builder.add(&element, diags);
    }
}

/// Runs parsed ahead of the one being added to the document: enough to keep
/// the rayon threads busy while the main thread adds, few enough that their
/// element trees stay small (about 64 kB of text each).
const RUNS_AHEAD: usize = 8;

/// Where [`read_runs`] puts what it reads.
struct Reading<'r, 'b, 's> {
    extractor: &'r crate::implicit::xml::Extractor,
    builder: &'r mut doc::DocumentBuilder<'b>,
    extracted: &'r mut crate::implicit::xml::Extracted<'s>,
    diags: &'r mut Diagnostics,
}

/// What a rayon thread read of one run for [`read_runs`].
enum RunRead<'s> {
    /// The run's part of the typed document, built there, with its findings
    /// (structure and document, element by element) in the serial order.
    Built(doc::Parts, Diagnostics),
    /// A run with an element the extractor may take: its elements with their
    /// structure findings, for the main thread to extract and add.
    Elements(Vec<(syntax::Element<'s>, Diagnostics)>),
}

/// [`read_element`] for every element of a split file, as a pipeline: the
/// rayon threads parse the runs, check their elements' structure and build
/// their parts of the typed document, the main thread takes the parts in file
/// order and moves them into the document ([`doc::DocumentBuilder::append`]);
/// the emptied parts go back to a rayon thread to be freed, and the rayon
/// threads free the element trees they parsed. A run with an element
/// the implicit path may take comes as elements, extracted and added on the
/// main thread. The root's check (`check_root`) runs beside them, its findings
/// put first. The findings come in the order of reading the file serially,
/// for any number of threads.
fn read_runs<'s>(
    runs: &syntax::Runs<'_, 's>,
    check_root: impl FnOnce(&mut Diagnostics) + Send,
    read: Reading<'_, '_, 's>,
) -> Result<(), syntax::Reparse> {
    type Checked<'s> = Result<RunRead<'s>, syntax::Reparse>;
    let Reading {
        extractor,
        builder,
        extracted,
        diags,
    } = read;
    let parts = builder.part_builder();
    let checked = |i: usize| -> Checked<'s> {
        let elements = runs.elements(i)?;
        if !elements.iter().all(|e| extractor.leaves(e)) {
            return Ok(RunRead::Elements(
                elements
                    .into_iter()
                    .map(|element| {
                        let mut found = Diagnostics::default();
                        check_top_level(&element, &mut found, &mut Default::default());
                        (element, found)
                    })
                    .collect(),
            ));
        }
        let (mut built, mut found) = (doc::Parts::for_elements(&elements), Diagnostics::default());
        let mut scratch = doc::structure::Scratch::default();
        for element in &elements {
            check_top_level(element, &mut found, &mut scratch);
            parts.add_part(element, &mut built, &mut found);
        }
        Ok(RunRead::Built(built, found))
    };
    let root_findings_at = diags.items.len();
    // A job's panic travels to this thread, which is waiting for its result.
    let (root_sender, root_receiver) = std::sync::mpsc::channel();
    let (sender, receiver) =
        std::sync::mpsc::channel::<(usize, std::thread::Result<Checked<'s>>)>();
    rayon::in_place_scope(|scope| {
        scope.spawn(move |_| {
            let found = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let mut found = Diagnostics::default();
                check_root(&mut found);
                found
            }));
            drop(root_sender.send(found));
        });
        let spawn = |i: usize| {
            let (sender, checked) = (sender.clone(), &checked);
            scope.spawn(move |_| {
                let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| checked(i)));
                // The receiver is gone only when reading stopped at a Reparse.
                drop(sender.send((i, run)));
            });
        };
        (0..runs.len().min(RUNS_AHEAD)).for_each(spawn);
        let mut arrived = std::collections::BTreeMap::new();
        for next in 0..runs.len() {
            let run = loop {
                if let Some(run) = arrived.remove(&next) {
                    break run;
                }
                let (i, run) = wait_for(&receiver)?;
                arrived.insert(i, run);
            };
            if next + RUNS_AHEAD < runs.len() {
                spawn(next + RUNS_AHEAD);
            }
            match run.unwrap_or_else(|panic| std::panic::resume_unwind(panic))? {
                RunRead::Built(mut built, found) => {
                    diags.extend(found);
                    builder.append(&mut built);
                    scope.spawn(move |_| drop(built));
                }
                RunRead::Elements(run) => {
                    let mut done = Vec::with_capacity(run.len());
                    for (element, found) in run {
                        diags.extend(found);
                        if let Some(element) = extractor.take(element, extracted) {
                            builder.add(&element, diags);
                            done.push(element);
                        }
                    }
                    scope.spawn(move |_| drop(done));
                }
            }
        }
        let root = wait_for(&root_receiver)?;
        let root = root.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        diags
            .items
            .splice(root_findings_at..root_findings_at, root.items);
        Ok(())
    })
}

/// The structure check of one top-level element (an unknown one is the
/// root's check to report), in the lists of `scratch`.
fn check_top_level<'e, 's>(
    element: &'e syntax::Element<'s>,
    found: &mut Diagnostics,
    scratch: &mut doc::structure::Scratch<'e, 's>,
) {
    if let Some(rule) = grammar::GEOMETRY.child_rule(element.name) {
        doc::structure::check_reusing(element, rule, found, scratch);
    }
}

/// The next message of a job of [`read_runs`]. On a rayon thread (the driver
/// called inside a caller's pool) it runs the pool's pending jobs, its own
/// among them, instead of blocking: a pool of one thread would wait forever.
fn wait_for<T>(receiver: &std::sync::mpsc::Receiver<T>) -> Result<T, syntax::Reparse> {
    loop {
        match receiver.try_recv() {
            Ok(message) => return Ok(message),
            Err(std::sync::mpsc::TryRecvError::Empty) => {
                if !matches!(rayon::yield_now(), Some(rayon::Yield::Executed)) {
                    // Nothing pending: the job is running on another thread.
                    return receiver.recv().map_err(|_| syntax::Reparse);
                }
            }
            Err(std::sync::mpsc::TryRecvError::Disconnected) => return Err(syntax::Reparse),
        }
    }
}

fn release(options: &Options) {
    if let Some(release) = options.release_memory {
        // The runs are read on the rayon threads, so much of what was just
        // freed lies in their heaps, which only they can hand back.
        rayon::broadcast(|_| release());
        release();
    }
}

/// Lowers the implicit elements; parameters they use are no longer unused (W006).
fn lower_implicit(
    source: &SourceFile,
    options: &Options,
    extracted: &crate::implicit::xml::Extracted,
    resolved: &resolve::Resolved,
    diags: &mut Diagnostics,
) -> (
    Vec<ImplicitSubdomain>,
    Vec<crate::implicit::xml::LoweredTrim>,
) {
    let folder = Path::new(&source.name)
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| std::path::PathBuf::from("."), Path::to_path_buf);
    let taken = |name: &str| resolved.object(name).is_some();
    let env = crate::implicit::xml::Env {
        source,
        parameters: &resolved.parameters,
        folder,
        allowed: &options.allowed_paths,
        taken: &taken,
    };
    let out = crate::implicit::xml::lower(extracted, &env, diags);
    diags.items.retain(|d| {
        d.code != Code::UnusedParameter
            || !d
                .span
                .is_some_and(|s| out.used_parameters.contains(source.snippet(s).trim()))
    });
    (out.subdomains, out.trims)
}

/// Gives each trimmed surface whose `<trim>` holds an R-function tree its F.
fn set_trims(model: &mut crate::ir::Model, trims: Vec<crate::implicit::xml::LoweredTrim>) {
    for t in trims {
        for s in model.trimmed.iter_mut().filter(|s| s.name == t.surface) {
            s.trim = Some(crate::trimmed::Trim::new(&t.ctx, t.root, t.negative));
        }
    }
}

/// Whole-model warnings: no subdomains, boundaries on no subdomain.
/// `defined_subdomains`: how many `<subdomain>` the document defined.
fn check_domain(
    document: &doc::Document,
    defined_subdomains: usize,
    lowered: &Lowered,
    diags: &mut Diagnostics,
) {
    let model = &lowered.model;
    if model.subdomains.is_empty() && defined_subdomains == 0 && !model.solids.is_empty() {
        diags.push(
            Diagnostic::new(
                Code::EmptySubdomainList,
                None,
                format!("the file defines {} solid{} but no <subdomain>, so it describes no computational domain", model.solids.len(), if model.solids.len() == 1 { "" } else { "s" }),
            )
            .with_help("add <subdomain name=\"…\"><solid ref=\"…\"/></subdomain> to describe the domain"),
        );
    }
    if model.boundaries.is_empty() {
        // Nothing to check below; the face sets are large on big models.
        return;
    }
    let bounding: std::collections::BTreeSet<usize> = model
        .subdomains
        .iter()
        .flat_map(|s| match &s.cells {
            SubdomainCells::Volume { boundary } => {
                boundary.iter().map(|f| f.face.index()).collect::<Vec<_>>()
            }
            SubdomainCells::Region { faces } => faces.iter().map(|f| f.index()).collect(),
        })
        .collect();
    let bounding_edges: std::collections::BTreeSet<usize> = if model.dimension == Dimension::Two {
        bounding
            .iter()
            .flat_map(|&f| {
                model.faces[f]
                    .loops
                    .iter()
                    .flatten()
                    .map(|e| e.edge.index())
            })
            .collect()
    } else {
        Default::default()
    };
    // A subdomain that failed to lower was reported; the faces it would have
    // bounded must not be called stray on top of that.
    if model.subdomains.len() < defined_subdomains {
        return;
    }
    for (b, def) in model.boundaries.iter().zip(&document.boundaries) {
        let stray_face = b.faces.iter().find(|f| !bounding.contains(&f.index()));
        let stray_edge = b
            .edges
            .iter()
            .find(|e| model.dimension == Dimension::Two && !bounding_edges.contains(&e.index()));
        let stray = stray_face
            .map(|f| model.face(*f).name.clone())
            .or_else(|| stray_edge.map(|e| model.edge(*e).name.clone()));
        if let Some(name) = stray {
            diags.push(
                Diagnostic::new(Code::BoundaryNotOnSubdomain, def.span, format!("boundary '{}' names '{name}', which bounds no subdomain", b.name))
                    .with_help("name faces on the boundary of a subdomain; faces made interior by a union bound nothing"),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_threads::on_threads;

    /// `count` spheres, each a subdomain; every 7th has an unknown attribute
    /// (E111, a structure finding), every 11th a malformed radius (a document
    /// finding) and every 13th repeats an earlier name (E201, resolution); an
    /// unknown element halfway is the root's finding.
    /// `tail` goes right before the root's end tag.
    fn spheres(count: usize, tail: &str) -> String {
        let mut xml = String::from("<geometry version=\"1\">\n");
        for i in 0..count {
            let name = if i % 13 == 12 { i - 1 } else { i };
            let extra = if i % 7 == 0 { " colour=\"red\"" } else { "" };
            let radius = if i % 11 == 0 { "0.3x" } else { "0.3" };
            if i == count / 2 {
                // The root's own check reports it (E110).
                xml.push_str("  <spere name=\"typo\"/>\n");
            }
            xml.push_str(&format!(
                "  <sphere name=\"s{name}\"{extra}><center x=\"{i}\" y=\"0\" z=\"0\"/><radius value=\"{radius}\"/></sphere>\n  <subdomain name=\"d{i}\"><solid ref=\"s{name}\"/></subdomain>\n"
            ));
        }
        xml.push_str(tail);
        xml.push_str("</geometry>\n");
        xml
    }

    fn checked_with(threads: usize, text: &str) -> Diagnostics {
        let source = SourceFile::new("many.xml".to_string(), text.to_string());
        on_threads(threads, || {
            check_source(source, &Options::default()).diagnostics
        })
    }

    /// Every kind of top-level element the typed document keeps, `count`
    /// times over: parameters, coordinate systems, boxes in them, spheres,
    /// subdomains (a union every 5th), boundaries, with malformed numbers
    /// (document findings), unknown attributes (structure findings) and, at
    /// a third, a trimmed surface (whose run the main thread must extract
    /// and add itself). `tail` goes right before the root's end tag.
    fn every_part(count: usize, tail: &str) -> String {
        let mut xml = String::from(
            "<geometry version=\"1\">\n  <basis_coordinate>\n    <coordinate name=\"X\"><value x1=\"0\" x2=\"1 +\"/></coordinate>\n  </basis_coordinate>\n",
        );
        for i in 0..count {
            if i == count / 3 {
                xml.push_str("  <sphere_surface name=\"cap\" radius=\"1.5\" from_latitude=\"-90\" to_latitude=\"90\"><trim equation=\"x^2 - 0.25\"/></sphere_surface>\n");
            }
            let radius = if i % 17 == 0 { "r*(" } else { "r + 0.1" };
            let extra = if i % 19 == 0 { " color=\"red\"" } else { "" };
            xml.push_str(&format!(
                "  <parameters><parameter name=\"p{i}\" value=\"{i}/2\"/></parameters>\n  <coordinate_system name=\"cs{i}\"><origin x=\"{i}\" y=\"0\" z=\"0\"/><rotation x=\"0\" y=\"0\" z=\"{i}\"/></coordinate_system>\n  <parallelepiped name=\"b{i}\" cs=\"cs{i}\"{extra}><first_point x=\"0\" y=\"0\" z=\"0\"/><second_point x=\"1\" y=\"p{i}\" z=\"1e0\"/></parallelepiped>\n  <sphere name=\"s{i}\"><center x=\"{i}\" y=\"3\" z=\"0\"/><radius value=\"{radius}\"/></sphere>\n"
            ));
            if i % 5 == 0 {
                xml.push_str(&format!("  <subdomain name=\"d{i}\" material=\"steel\"><union><solid ref=\"b{i}\"/><solid ref=\"s{i}\"/></union></subdomain>\n"));
            } else {
                xml.push_str(&format!(
                    "  <subdomain name=\"d{i}\"><solid ref=\"s{i}\"/></subdomain>\n"
                ));
            }
            if i % 30 == 0 {
                xml.push_str(&format!(
                    "  <boundary name=\"g{i}\" faces=\"b{i}.xmin  s{i}.surface\"/>\n"
                ));
            }
        }
        xml.push_str(tail);
        xml.push_str("</geometry>\n");
        xml
    }

    fn read_with(threads: usize, text: &str) -> (doc::Document, Diagnostics) {
        let source = SourceFile::new("parts.xml".to_string(), text.to_string());
        on_threads(threads, || {
            let mut diags = Diagnostics::default();
            let (document, _) = read(&source, &Options::default(), &mut diags).expect("reads");
            (document, diags)
        })
    }

    #[test]
    fn documents_built_on_threads_are_the_whole_reads_document() {
        let split = every_part(1_500, "");
        let source = SourceFile::new("parts.xml".to_string(), split.clone());
        let parsed = syntax::parse_document(&source, &Limits::default()).expect("parses");
        let runs = parsed.runs().expect("the file is read in runs").len();
        assert!(runs > RUNS_AHEAD, "{runs} runs");
        let whole = every_part(1_500, "  <!-- parsed whole -->\n");

        let (serial, found) = read_with(1, &whole);
        assert_eq!(serial.parameters.len(), 1_500);
        assert_eq!(serial.basis.len(), 2);
        assert_eq!(serial.coordinate_systems.len(), 1_500);
        // The boxes and spheres; the trimmed surface is an object too.
        assert_eq!(serial.objects.len(), 3_001);
        assert_eq!(serial.subdomains.len(), 1_500);
        assert_eq!(serial.boundaries.len(), 50);
        let count = |code: Code| found.items.iter().filter(|d| d.code == code).count();
        assert_eq!(count(Code::BadExpression), 1 + 89);
        assert_eq!(count(Code::UnknownAttribute), 79);
        for threads in [1, 2, 3] {
            let (document, diags) = read_with(threads, &split);
            assert!(document == serial, "the document on {threads} threads");
            assert_eq!(diags.items, found.items, "{threads} threads");
        }
    }

    #[test]
    fn runs_read_on_threads_give_the_whole_reads_diagnostics() {
        let split = spheres(5_000, "");
        let source = SourceFile::new("many.xml".to_string(), split.clone());
        let parsed = syntax::parse_document(&source, &Limits::default()).expect("parses");
        let runs = parsed.runs().expect("the file is read in runs").len();
        assert!(runs > RUNS_AHEAD, "{runs} runs");
        // A comment at the top level makes the file parse whole and read
        // serially, with every span before it the same.
        let whole = spheres(5_000, "  <!-- parsed whole -->\n");
        let source = SourceFile::new("many.xml".to_string(), whole.clone());
        let parsed = syntax::parse_document(&source, &Limits::default()).expect("parses");
        assert!(parsed.runs().is_none());

        let one = checked_with(1, &split);
        let count = |code: Code| one.items.iter().filter(|d| d.code == code).count();
        assert_eq!(count(Code::UnknownAttribute), 715);
        assert_eq!(count(Code::DuplicateName), 384);
        assert_eq!(count(Code::BadExpression), 455);
        assert_eq!(count(Code::UnknownElement), 1);
        assert_eq!(one.items, checked_with(3, &split).items);
        assert_eq!(one.items, checked_with(1, &whole).items);
        assert_eq!(one.items, checked_with(2, &whole).items);
    }
}
