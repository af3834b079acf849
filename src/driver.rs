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
    let resolved = resolve::resolve(source, &document, &options.overrides, diags);
    // Everything later reads the resolved objects, not the document's: on large
    // files they are a fifth of the peak memory while the model is lowered.
    document.objects = Vec::new();
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
    if let Some(version) = root.attribute("version") {
        if version.value.trim() != "1" {
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
    // The root's check reports unknown elements; only known ones go deeper.
    doc::structure::check_element_heads(&root, &heads, &grammar::GEOMETRY, diags);
    let extractor = crate::implicit::xml::Extractor::new(&root, &heads);
    let mut builder = doc::DocumentBuilder::new(source, &root, &options.expressions);
    let subdomains = heads.iter().filter(|h| h.name == "subdomain").count();
    builder.reserve(heads.len() - subdomains, subdomains);
    drop(heads);
    let mut extracted = crate::implicit::xml::Extracted::default();
    for element in parsed.top_level() {
        let element = element?;
        if let Some(rule) = grammar::GEOMETRY.child_rule(element.name) {
            doc::structure::check(&element, rule, diags);
        }
        if let Some(element) = extractor.take(element, &mut extracted) {
            builder.add(&element, diags);
        }
    }
    Ok((builder.finish(), extracted))
}

fn release(options: &Options) {
    if let Some(release) = options.release_memory {
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
