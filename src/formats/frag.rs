//! `.frag.xml`: the mesh's structure for solvers that read the mesh file
//! itself elsewhere — vertices, edges, faces with triangle counts and areas,
//! subdomains, fragments Γ(k,k') with their pairs, the incidence matrices
//! M_VE, M_EF, M_FD, and the name of the mesh file. `schema/frag.xsd`
//! describes it; [`read_frag_xml`] reads it back into the same
//! [`FragDocument`] the writer builds, so the two stay in step.

use super::groups;
use super::{MeshWriter, Warning, WriteError, WriteOptions, count, fmt_num, warning};
use crate::mesh::Mesh;
use crate::span::SourceFile;
use crate::syntax::{self, Element, Limits};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write;

pub(crate) struct FragXml;

/// The version written and the only one read.
pub const FRAG_VERSION: &str = "1";

#[derive(Debug, Clone, PartialEq)]
pub struct FragVertex {
    pub name: String,
    pub node: u32,
}

/// An edge (or a fragment in 2D): how many segments, how long.
#[derive(Debug, Clone, PartialEq)]
pub struct FragEdge {
    pub name: String,
    pub segments: usize,
    pub length: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct FragFace {
    pub name: String,
    pub triangles: usize,
    pub area: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct FragSubdomain {
    pub name: String,
    pub material: Option<String>,
}

/// A fragment: in 3D its faces, triangle count and area; in 2D its edges,
/// segment count and length (`elements` and `measure` hold either).
#[derive(Debug, Clone, PartialEq)]
pub struct FragFragment {
    pub name: String,
    pub subdomain: u32,
    /// `None`: the exterior.
    pub other: Option<u32>,
    pub faces: Vec<u32>,
    pub edges: Vec<u32>,
    pub elements: usize,
    pub measure: f64,
}

/// A sparse signed matrix, entries sorted by (row, col): ±1 by orientation,
/// 2 for an entity used both ways (as in `ir::incidence`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FragMatrix {
    pub rows: usize,
    pub cols: usize,
    pub entries: Vec<(u32, u32, i8)>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct FragDocument {
    pub dimension: u8,
    pub nodes: usize,
    pub mesh_file: Option<String>,
    pub vertices: Vec<FragVertex>,
    pub edges: Vec<FragEdge>,
    pub faces: Vec<FragFace>,
    pub subdomains: Vec<FragSubdomain>,
    pub fragments: Vec<FragFragment>,
    /// Vertex i bounds edge j: −1 begin, +1 end, 2 both.
    pub m_ve: FragMatrix,
    /// Edge i bounds face j: +1 forward in its loops, −1 backward, 2 both.
    pub m_ef: FragMatrix,
    /// Face i bounds subdomain j: +1 outward, −1 inward (3D); +1 member (2D).
    pub m_fd: FragMatrix,
}

/// Collects the directions an entity is used in (see `FragMatrix`).
#[derive(Default)]
struct Signs(BTreeMap<(u32, u32), (bool, bool)>);

impl Signs {
    fn add(&mut self, row: u32, col: u32, positive: bool) {
        let slot = self.0.entry((row, col)).or_default();
        if positive {
            slot.0 = true;
        } else {
            slot.1 = true;
        }
    }

    fn matrix(self, rows: usize, cols: usize) -> FragMatrix {
        let entries = self
            .0
            .into_iter()
            .map(|((r, c), both)| {
                let v = match both {
                    (true, true) => 2,
                    (true, false) => 1,
                    _ => -1,
                };
                (r, c, v)
            })
            .collect();
        FragMatrix {
            rows,
            cols,
            entries,
        }
    }
}

impl FragDocument {
    /// The document of a mesh; `check`ed meshes only (indices in range).
    fn of(mesh: &Mesh, mesh_file: Option<String>) -> FragDocument {
        let vertex_of_node: BTreeMap<u32, u32> = mesh
            .vertices
            .iter()
            .enumerate()
            .rev()
            .map(|(i, v)| (v.node, i as u32))
            .collect();
        let mut ve = Signs::default();
        for (j, e) in mesh.edges.iter().enumerate() {
            if let Some(&v) = e.nodes.first().and_then(|n| vertex_of_node.get(n)) {
                ve.add(v, j as u32, false);
            }
            if let Some(&v) = e.nodes.last().and_then(|n| vertex_of_node.get(n)) {
                ve.add(v, j as u32, true);
            }
        }
        let mut ef = Signs::default();
        for (j, f) in mesh.faces.iter().enumerate() {
            for &(e, fwd) in &f.boundary {
                ef.add(e, j as u32, fwd);
            }
        }
        let mut fd = Signs::default();
        for (j, s) in mesh.subdomains.iter().enumerate() {
            for &(f, out) in &s.faces {
                fd.add(f, j as u32, out || mesh.dimension == 2);
            }
        }
        let three = mesh.dimension == 3;
        FragDocument {
            dimension: mesh.dimension,
            nodes: mesh.nodes.len(),
            mesh_file,
            vertices: mesh
                .vertices
                .iter()
                .map(|v| FragVertex {
                    name: v.name.clone(),
                    node: v.node,
                })
                .collect(),
            edges: mesh
                .edges
                .iter()
                .map(|e| FragEdge {
                    name: e.name.clone(),
                    segments: e.nodes.len().saturating_sub(1),
                    length: groups::length(mesh, &e.nodes),
                })
                .collect(),
            faces: mesh
                .faces
                .iter()
                .enumerate()
                .map(|(i, f)| FragFace {
                    name: f.name.clone(),
                    triangles: f.triangles.len(),
                    area: groups::face_area(mesh, i as u32),
                })
                .collect(),
            subdomains: mesh
                .subdomains
                .iter()
                .map(|s| FragSubdomain {
                    name: s.name.clone(),
                    material: s.material.clone(),
                })
                .collect(),
            fragments: mesh
                .fragments
                .iter()
                .map(|fr| {
                    let (elements, measure) = if three {
                        (
                            fr.faces
                                .iter()
                                .map(|&f| mesh.faces[f as usize].triangles.len())
                                .sum(),
                            fr.faces.iter().map(|&f| groups::face_area(mesh, f)).sum(),
                        )
                    } else {
                        (
                            fr.edges
                                .iter()
                                .map(|&e| mesh.edges[e as usize].nodes.len().saturating_sub(1))
                                .sum(),
                            fr.edges
                                .iter()
                                .map(|&e| groups::length(mesh, &mesh.edges[e as usize].nodes))
                                .sum(),
                        )
                    };
                    FragFragment {
                        name: fr.name.clone(),
                        subdomain: fr.subdomain,
                        other: fr.other,
                        faces: fr.faces.clone(),
                        edges: fr.edges.clone(),
                        elements,
                        measure,
                    }
                })
                .collect(),
            m_ve: ve.matrix(mesh.vertices.len(), mesh.edges.len()),
            m_ef: ef.matrix(mesh.edges.len(), mesh.faces.len()),
            m_fd: fd.matrix(mesh.faces.len(), mesh.subdomains.len()),
        }
    }

    /// The document as XML text. Counts the characters XML cannot hold.
    fn to_xml(&self, replaced: &mut usize) -> String {
        let mut x = String::new();
        let mut esc = |s: &str| escape(s, replaced);
        let _ = writeln!(x, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
        let _ = writeln!(
            x,
            "<frag version=\"{FRAG_VERSION}\" dimension=\"{}\" nodes=\"{}\">",
            self.dimension, self.nodes
        );
        if let Some(file) = &self.mesh_file {
            let _ = writeln!(x, "  <mesh file=\"{}\"/>", esc(file));
        }
        let _ = writeln!(x, "  <vertices>");
        for (i, v) in self.vertices.iter().enumerate() {
            let _ = writeln!(
                x,
                "    <vertex id=\"{i}\" name=\"{}\" node=\"{}\"/>",
                esc(&v.name),
                v.node
            );
        }
        let _ = writeln!(x, "  </vertices>");
        let _ = writeln!(x, "  <edges>");
        for (i, e) in self.edges.iter().enumerate() {
            let _ = writeln!(
                x,
                "    <edge id=\"{i}\" name=\"{}\" segments=\"{}\" length=\"{}\"/>",
                esc(&e.name),
                e.segments,
                fmt_num(e.length)
            );
        }
        let _ = writeln!(x, "  </edges>");
        let _ = writeln!(x, "  <faces>");
        for (i, f) in self.faces.iter().enumerate() {
            let _ = writeln!(
                x,
                "    <face id=\"{i}\" name=\"{}\" triangles=\"{}\" area=\"{}\"/>",
                esc(&f.name),
                f.triangles,
                fmt_num(f.area)
            );
        }
        let _ = writeln!(x, "  </faces>");
        let _ = writeln!(x, "  <subdomains>");
        for (i, s) in self.subdomains.iter().enumerate() {
            let material = s
                .material
                .as_ref()
                .map(|m| format!(" material=\"{}\"", esc(m)))
                .unwrap_or_default();
            let _ = writeln!(
                x,
                "    <subdomain id=\"{i}\" name=\"{}\"{material}/>",
                esc(&s.name)
            );
        }
        let _ = writeln!(x, "  </subdomains>");
        let _ = writeln!(x, "  <fragments>");
        for (i, fr) in self.fragments.iter().enumerate() {
            let other = fr.other.map_or("exterior".to_string(), |o| o.to_string());
            let list = |ids: &[u32]| ids.iter().map(u32::to_string).collect::<Vec<_>>().join(" ");
            let (parts, elements, measure) = if self.dimension == 3 {
                (
                    format!("faces=\"{}\"", list(&fr.faces)),
                    "triangles",
                    "area",
                )
            } else {
                (
                    format!("edges=\"{}\"", list(&fr.edges)),
                    "segments",
                    "length",
                )
            };
            let _ = writeln!(
                x,
                "    <fragment id=\"{i}\" name=\"{}\" subdomain=\"{}\" other=\"{other}\" {parts} {elements}=\"{}\" {measure}=\"{}\"/>",
                esc(&fr.name),
                fr.subdomain,
                fr.elements,
                fmt_num(fr.measure)
            );
        }
        let _ = writeln!(x, "  </fragments>");
        for (name, m) in [
            ("M_VE", &self.m_ve),
            ("M_EF", &self.m_ef),
            ("M_FD", &self.m_fd),
        ] {
            let _ = writeln!(
                x,
                "  <incidence name=\"{name}\" rows=\"{}\" cols=\"{}\">",
                m.rows, m.cols
            );
            for (r, c, v) in &m.entries {
                let _ = writeln!(x, "    <e row=\"{r}\" col=\"{c}\" value=\"{v}\"/>");
            }
            let _ = writeln!(x, "  </incidence>");
        }
        let _ = writeln!(x, "</frag>");
        x
    }
}

/// Escapes an attribute value. Whitespace other than a space is written as a
/// character reference so it survives attribute normalisation; characters XML
/// 1.0 cannot hold at all become U+FFFD and are counted.
fn escape(s: &str, replaced: &mut usize) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {
                *replaced += 1;
                out.push('\u{FFFD}');
            }
            c => out.push(c),
        }
    }
    out
}

impl MeshWriter for FragXml {
    fn name(&self) -> &'static str {
        "frag.xml"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["frag.xml"]
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        groups::check(mesh)?;
        let doc = FragDocument::of(mesh, options.mesh_file.clone());
        let mut replaced = 0;
        let text = doc.to_xml(&mut replaced);
        out.write_all(text.as_bytes())?;
        let mut warnings = Vec::new();
        if replaced > 0 {
            warnings.push(warning(
                "frag.xml",
                format!(
                    "XML cannot hold control characters: {} in names replaced by U+FFFD",
                    count(replaced, "character")
                ),
            ));
        }
        if options.mesh_file.is_none() {
            warnings.push(warning(
                "frag.xml",
                "no mesh file given: the document refers to none",
            ));
        }
        Ok(warnings)
    }
}

/// Why a `.frag.xml` could not be read, with its place as `line:column`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{location}: {message}")]
pub struct FragReadError {
    pub location: String,
    pub message: String,
}

/// Reads a `.frag.xml` document. `name` is used in error locations.
pub fn read_frag_xml(name: &str, text: &str) -> Result<FragDocument, FragReadError> {
    let source = SourceFile::new(name, text);
    let root = syntax::parse(&source, &Limits::default()).map_err(|d| FragReadError {
        location: d
            .span
            .map_or_else(|| name.to_string(), |s| at(&source, s.start as usize)),
        message: d.message,
    })?;
    Reader { source: &source }.document(&root)
}

fn at(source: &SourceFile, offset: usize) -> String {
    let lc = source.line_col(offset);
    format!("{}:{}:{}", source.name, lc.line, lc.column)
}

struct Reader<'a> {
    source: &'a SourceFile,
}

impl Reader<'_> {
    fn error<T>(&self, element: &Element, message: impl Into<String>) -> Result<T, FragReadError> {
        Err(FragReadError {
            location: at(self.source, element.span.start as usize),
            message: message.into(),
        })
    }

    fn text<'e>(&self, element: &'e Element, name: &str) -> Result<&'e str, FragReadError> {
        match element.attribute(name) {
            Some(a) => Ok(&a.value),
            None => self.error(
                element,
                format!("<{}> has no `{name}` attribute", element.name),
            ),
        }
    }

    fn number<T: std::str::FromStr>(
        &self,
        element: &Element,
        name: &str,
    ) -> Result<T, FragReadError> {
        let text = self.text(element, name)?;
        match text.trim().parse() {
            Ok(v) => Ok(v),
            Err(_) => self.error(
                element,
                format!("`{name}` of <{}> is not a number: `{text}`", element.name),
            ),
        }
    }

    fn ids(&self, element: &Element, name: &str) -> Result<Vec<u32>, FragReadError> {
        let Some(attr) = element.attribute(name) else {
            return Ok(Vec::new());
        };
        attr.value
            .split_whitespace()
            .map(|t| {
                t.parse()
                    .or_else(|_| self.error(element, format!("`{name}` holds `{t}`, not an index")))
            })
            .collect()
    }

    /// The children of the one `<list>` child, each named `item`.
    fn list<'e>(
        &self,
        root: &'e Element,
        list: &'e str,
        item: &str,
    ) -> Result<Vec<&'e Element<'e>>, FragReadError> {
        let Some(parent) = root.children_named(list).next() else {
            return self.error(root, format!("<{}> has no <{list}>", root.name));
        };
        parent
            .children
            .iter()
            .map(|c| {
                if c.name == item {
                    Ok(c)
                } else {
                    self.error(
                        c,
                        format!("<{}> in <{list}>: only <{item}> belongs there", c.name),
                    )
                }
            })
            .collect()
    }

    fn matrix(&self, root: &Element, name: &str) -> Result<FragMatrix, FragReadError> {
        let Some(m) = root
            .children_named("incidence")
            .find(|m| m.attribute("name").is_some_and(|a| a.value == name))
        else {
            return self.error(root, format!("no <incidence name=\"{name}\">"));
        };
        let mut entries = Vec::with_capacity(m.children.len());
        for e in &m.children {
            entries.push((
                self.number(e, "row")?,
                self.number(e, "col")?,
                self.number(e, "value")?,
            ));
        }
        Ok(FragMatrix {
            rows: self.number(m, "rows")?,
            cols: self.number(m, "cols")?,
            entries,
        })
    }

    fn document(&self, root: &Element) -> Result<FragDocument, FragReadError> {
        if root.name != "frag" {
            return self.error(
                root,
                format!("the root element is <{}>, not <frag>", root.name),
            );
        }
        let version = self.text(root, "version")?;
        if version != FRAG_VERSION {
            return self.error(
                root,
                format!("version {version} is not supported (only {FRAG_VERSION})"),
            );
        }
        let dimension: u8 = self.number(root, "dimension")?;
        if dimension != 2 && dimension != 3 {
            return self.error(root, format!("dimension {dimension}: 2 or 3 expected"));
        }
        let mesh_file = match root.children_named("mesh").next() {
            Some(m) => Some(self.text(m, "file")?.to_string()),
            None => None,
        };
        let name = |e: &Element| self.text(e, "name").map(str::to_string);
        let vertices = self
            .list(root, "vertices", "vertex")?
            .into_iter()
            .map(|e| {
                Ok(FragVertex {
                    name: name(e)?,
                    node: self.number(e, "node")?,
                })
            })
            .collect::<Result<_, FragReadError>>()?;
        let edges = self
            .list(root, "edges", "edge")?
            .into_iter()
            .map(|e| {
                Ok(FragEdge {
                    name: name(e)?,
                    segments: self.number(e, "segments")?,
                    length: self.number(e, "length")?,
                })
            })
            .collect::<Result<_, FragReadError>>()?;
        let faces = self
            .list(root, "faces", "face")?
            .into_iter()
            .map(|e| {
                Ok(FragFace {
                    name: name(e)?,
                    triangles: self.number(e, "triangles")?,
                    area: self.number(e, "area")?,
                })
            })
            .collect::<Result<_, FragReadError>>()?;
        let subdomains = self
            .list(root, "subdomains", "subdomain")?
            .into_iter()
            .map(|e| {
                Ok(FragSubdomain {
                    name: name(e)?,
                    material: e.attribute("material").map(|a| a.value.to_string()),
                })
            })
            .collect::<Result<_, FragReadError>>()?;
        let (elements, measure) = if dimension == 3 {
            ("triangles", "area")
        } else {
            ("segments", "length")
        };
        let fragments = self
            .list(root, "fragments", "fragment")?
            .into_iter()
            .map(|e| {
                let other = match self.text(e, "other")? {
                    "exterior" => None,
                    _ => Some(self.number(e, "other")?),
                };
                Ok(FragFragment {
                    name: name(e)?,
                    subdomain: self.number(e, "subdomain")?,
                    other,
                    faces: self.ids(e, "faces")?,
                    edges: self.ids(e, "edges")?,
                    elements: self.number(e, elements)?,
                    measure: self.number(e, measure)?,
                })
            })
            .collect::<Result<_, FragReadError>>()?;
        Ok(FragDocument {
            dimension,
            nodes: self.number(root, "nodes")?,
            mesh_file,
            vertices,
            edges,
            faces,
            subdomains,
            fragments,
            m_ve: self.matrix(root, "M_VE")?,
            m_ef: self.matrix(root, "M_EF")?,
            m_fd: self.matrix(root, "M_FD")?,
        })
    }
}

/// The document the `.frag.xml` writer would write for `mesh`, for callers
/// that want the data without the XML (and for round-trip tests).
pub fn frag_document(mesh: &Mesh, mesh_file: Option<String>) -> Result<FragDocument, WriteError> {
    groups::check(mesh)?;
    Ok(FragDocument::of(mesh, mesh_file))
}
