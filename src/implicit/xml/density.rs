//! `<density_volume>`: a 3D matrix of samples from a raw file (type, byte
//! order, dims, spacing and origin as attributes) or an NRRD file (the same
//! from its header), minus the level, on the grid of the samples. Trilinear
//! interpolation of the samples is the function, so the polygonizer's linear
//! edge crossings are exact for it.

// User-controlled bytes and values: no panicking index (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

use super::{Env, paths, settings};
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::implicit::polygonize::Grid;
use crate::span::Span;
use crate::syntax::{Attribute, Element};
use std::collections::BTreeSet;
use std::io::Read;
use std::path::Path;

/// Most samples read (2²⁷: a 512³ volume; 1 GiB as f64).
pub const MAX_SAMPLES: u64 = 1 << 27;
/// Longest NRRD header read.
const MAX_HEADER: usize = 1 << 16;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleType {
    U8,
    U16,
    I16,
    F32,
}

impl SampleType {
    pub fn size(self) -> usize {
        match self {
            SampleType::U8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::F32 => 4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "u8",
            SampleType::U16 => "u16",
            SampleType::I16 => "i16",
            SampleType::F32 => "f32",
        }
    }

    fn parse(text: &str) -> Option<SampleType> {
        Some(match text {
            "u8" => SampleType::U8,
            "u16" => SampleType::U16,
            "i16" => SampleType::I16,
            "f32" => SampleType::F32,
            _ => return None,
        })
    }

    /// NRRD's spellings of the four types.
    fn parse_nrrd(text: &str) -> Option<SampleType> {
        Some(match text {
            "uchar" | "unsigned char" | "uint8" | "uint8_t" => SampleType::U8,
            "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
                SampleType::U16
            }
            "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
                SampleType::I16
            }
            "float" => SampleType::F32,
            _ => return None,
        })
    }
}

/// How the samples lie in the file and in space.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub ty: SampleType,
    pub big_endian: bool,
    pub dims: [usize; 3],
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
}

impl Layout {
    fn bytes(&self) -> Option<u64> {
        let n = self
            .dims
            .iter()
            .try_fold(1u64, |acc, &d| acc.checked_mul(d as u64))?;
        n.checked_mul(self.ty.size() as u64)
    }

    fn grid(&self) -> Grid {
        let mut grid = Grid {
            min: self.origin,
            max: self.origin,
            cells: [0; 3],
        };
        let axes = grid.max.iter_mut().zip(grid.cells.iter_mut());
        for (((max, cells), origin), (spacing, dims)) in axes
            .zip(self.origin)
            .zip(self.spacing.iter().zip(self.dims))
        {
            *max = origin + spacing * (dims - 1) as f64;
            *cells = dims - 1;
        }
        grid
    }
}

/// Decodes samples (x fastest) into values minus `level`.
pub fn decode(bytes: &[u8], layout: &Layout, level: f64) -> Vec<f64> {
    let size = layout.ty.size();
    bytes
        .chunks_exact(size)
        .map(|c| {
            // `chunks_exact(size)` gives exactly `size` bytes: the arrays never fail.
            let two = <[u8; 2]>::try_from(c).unwrap_or_default();
            let four = <[u8; 4]>::try_from(c).unwrap_or_default();
            let v = match (layout.ty, layout.big_endian) {
                (SampleType::U8, _) => c.first().copied().unwrap_or(0) as f64,
                (SampleType::U16, false) => u16::from_le_bytes(two) as f64,
                (SampleType::U16, true) => u16::from_be_bytes(two) as f64,
                (SampleType::I16, false) => i16::from_le_bytes(two) as f64,
                (SampleType::I16, true) => i16::from_be_bytes(two) as f64,
                (SampleType::F32, false) => f32::from_le_bytes(four) as f64,
                (SampleType::F32, true) => f32::from_be_bytes(four) as f64,
            };
            v - level
        })
        .collect()
}

fn bad(code: Code, span: Span, message: String) -> Diagnostic {
    Diagnostic::new(code, span, message)
}

/// Three numbers separated by white space (`dims`, `spacing`, `origin`).
fn triple(text: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = text
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()?;
    <[f64; 3]>::try_from(v).ok()
}

fn check_dims(dims: [f64; 3]) -> Option<[usize; 3]> {
    dims.iter()
        .all(|d| d.fract() == 0.0 && (2.0..=1_000_000.0).contains(d))
        .then(|| dims.map(|d| d as usize))
}

/// The layout from a raw file's attributes.
fn raw_layout(e: &Element, diags: &mut Diagnostics) -> Option<Layout> {
    let mut ok = true;
    let mut need = |name: &str| {
        let a = e.attribute(name);
        if a.is_none() {
            diags.push(bad(
                Code::ImplicitDensityAttribute,
                e.name_span,
                format!("a raw <density_volume> needs {name}=\"…\" (or give an NRRD file)"),
            ));
            ok = false;
        }
        a
    };
    let ty = need("type").map(|a| SampleType::parse(a.value.trim()));
    let dims_attr = need("dims");
    if !ok {
        return None;
    }
    let ty = ty.flatten()?;
    let dims_attr = dims_attr?;
    let Some(dims) = triple(&dims_attr.value).and_then(check_dims) else {
        diags.push(bad(
            Code::ImplicitDensityAttribute,
            dims_attr.value_span,
            format!(
                "dims=\"{}\": give three whole numbers of samples, each at least 2",
                dims_attr.value
            ),
        ));
        return None;
    };
    let mut read3 = |name: &str, default: [f64; 3], positive: bool| -> Option<[f64; 3]> {
        let Some(a) = e.attribute(name) else {
            return Some(default);
        };
        match triple(&a.value).filter(|v| !positive || v.iter().all(|x| *x > 0.0)) {
            Some(v) => Some(v),
            None => {
                diags.push(bad(
                    Code::ImplicitDensityAttribute,
                    a.value_span,
                    format!(
                        "{name}=\"{}\": give three {}numbers separated by spaces",
                        a.value,
                        if positive { "positive " } else { "" }
                    ),
                ));
                None
            }
        }
    };
    let spacing = read3("spacing", [1.0; 3], true);
    let origin = read3("origin", [0.0; 3], false);
    Some(Layout {
        ty,
        big_endian: e
            .attribute("endian")
            .is_some_and(|a| a.value.trim() == "big"),
        dims,
        spacing: spacing?,
        origin: origin?,
    })
}

/// An NRRD header: the layout, the header's length, and a detached data file.
#[derive(Debug, Clone, PartialEq)]
pub struct Nrrd {
    pub layout: Layout,
    pub header_len: usize,
    pub data_file: Option<String>,
}

/// Parses an NRRD header (the text up to the first empty line). Errors carry
/// the 1-based line number.
pub fn parse_nrrd(bytes: &[u8]) -> Result<Nrrd, (usize, String)> {
    let head = bytes.get(..MAX_HEADER).unwrap_or(bytes);
    let mut ty = None;
    let mut dims = None;
    let mut dimension = None;
    let mut big_endian = None;
    let mut encoding = None;
    let mut spacing = None;
    let mut origin = None;
    let mut data_file = None;
    let mut pos = 0;
    let mut line_no = 0;
    let header_len = loop {
        let rest = head.get(pos..).unwrap_or_default();
        let Some(nl) = rest.iter().position(|&b| b == b'\n') else {
            return Err((
                line_no + 1,
                "the header does not end with an empty line within 64 KiB".into(),
            ));
        };
        line_no += 1;
        let raw = rest.get(..nl).unwrap_or_default();
        pos += nl + 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| (line_no, "the header line is not text".to_string()))?
            .trim_end_matches('\r');
        if line_no == 1 {
            if !(line.starts_with("NRRD000") && line.len() == 8) {
                return Err((
                    1,
                    format!("'{line}' is not an NRRD magic line (NRRD0001 … NRRD0005)"),
                ));
            }
            continue;
        }
        if line.is_empty() {
            break pos;
        }
        if line.starts_with('#') || line.contains(":=") {
            continue;
        }
        let Some((key, value)) = line.split_once(": ") else {
            return Err((line_no, format!("'{line}' is not a 'field: value' line")));
        };
        let value = value.trim();
        let err = |m: String| Err((line_no, m));
        match key.trim() {
            "type" => match SampleType::parse_nrrd(value) {
                Some(t) => ty = Some(t),
                None => {
                    return err(format!(
                        "type '{value}' is not read; use uchar, ushort, short or float"
                    ));
                }
            },
            "dimension" => dimension = Some((value.to_string(), line_no)),
            "sizes" => match triple(value).and_then(check_dims) {
                Some(d) => dims = Some(d),
                None => {
                    return err(format!(
                        "sizes '{value}': give three whole numbers, each at least 2"
                    ));
                }
            },
            "endian" => match value {
                "little" => big_endian = Some(false),
                "big" => big_endian = Some(true),
                _ => return err(format!("endian '{value}': use little or big")),
            },
            "encoding" => encoding = Some((value.to_string(), line_no)),
            "spacings" => match triple(value).filter(|v| v.iter().all(|x| *x > 0.0)) {
                Some(s) => spacing = Some(s),
                None => return err(format!("spacings '{value}': give three positive numbers")),
            },
            "space directions" => match directions(value) {
                Some(s) => spacing = Some(s),
                None => {
                    return err(format!(
                        "space directions '{value}': only axis-aligned vectors like (1,0,0) (0,1,0) (0,0,1) are read"
                    ));
                }
            },
            "space origin" => match triple(value.trim_start_matches('(').trim_end_matches(')')) {
                Some(o) => origin = Some(o),
                None => return err(format!("space origin '{value}': give (x,y,z)")),
            },
            "data file" | "datafile" => data_file = Some(value.to_string()),
            _ => {}
        }
    };
    let missing = |what: &str| (line_no, format!("the header has no '{what}' field"));
    match dimension {
        Some((d, _)) if d == "3" => {}
        Some((d, line)) => return Err((line, format!("dimension {d}: only 3 is read"))),
        None => return Err(missing("dimension")),
    }
    let ty = ty.ok_or_else(|| missing("type"))?;
    match encoding {
        Some((e, _)) if e == "raw" => {}
        Some((other, line)) => {
            return Err((line, format!("encoding '{other}' is not read; only raw")));
        }
        None => return Err(missing("encoding")),
    }
    if ty.size() > 1 && big_endian.is_none() {
        return Err(missing("endian"));
    }
    Ok(Nrrd {
        layout: Layout {
            ty,
            big_endian: big_endian.unwrap_or(false),
            dims: dims.ok_or_else(|| missing("sizes"))?,
            spacing: spacing.unwrap_or([1.0; 3]),
            origin: origin.unwrap_or([0.0; 3]),
        },
        header_len,
        data_file,
    })
}

/// Axis-aligned `(a,0,0) (0,b,0) (0,0,c)` → spacings |a|, |b|, |c|.
fn directions(value: &str) -> Option<[f64; 3]> {
    let vectors: Vec<[f64; 3]> = value
        .split(')')
        .map(|s| s.trim().trim_start_matches('('))
        .filter(|s| !s.is_empty())
        .map(triple)
        .collect::<Option<_>>()?;
    let vectors = <[[f64; 3]; 3]>::try_from(vectors).ok()?;
    let mut out = [0.0; 3];
    for (a, (v, slot)) in vectors.iter().zip(out.iter_mut()).enumerate() {
        let along = v.get(a).copied().unwrap_or(0.0);
        let across = v.iter().enumerate().any(|(b, x)| b != a && *x != 0.0);
        if across || along <= 0.0 {
            return None;
        }
        *slot = along;
    }
    Some(out)
}

fn is_nrrd(path: &Path, first: &[u8]) -> bool {
    first.starts_with(b"NRRD")
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("nrrd") || e.eq_ignore_ascii_case("nhdr"))
}

/// Reads the volume of a `<density_volume>`: its grid and samples minus the level.
pub(super) fn read(
    e: &Element,
    env: &Env,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<(Grid, Vec<f64>)> {
    let file = e.attribute("file")?;
    // Absent (structure already reported it) or bad (reported here).
    let level = settings::constant(e, "level", env, used, diags)??;
    let path = paths::resolve(env, file).map_err(|d| diags.push(d)).ok()?;
    let unreadable = |err: std::io::Error| {
        bad(
            Code::ImplicitFileUnreadable,
            file.value_span,
            format!("cannot read '{}': {err}", file.value.trim()),
        )
    };
    let mut handle = std::fs::File::open(&path)
        .map_err(|err| diags.push(unreadable(err)))
        .ok()?;
    let len = handle
        .metadata()
        .map_err(|err| diags.push(unreadable(err)))
        .ok()?
        .len();
    let mut head = vec![0u8; (len as usize).min(MAX_HEADER)];
    handle
        .read_exact(&mut head)
        .map_err(|err| diags.push(unreadable(err)))
        .ok()?;
    let (layout, data_path, offset) = if is_nrrd(&path, &head) {
        let given: Vec<&Attribute> = ["type", "endian", "dims", "spacing", "origin"]
            .iter()
            .filter_map(|n| e.attribute(n))
            .collect();
        if let Some(a) = given.first() {
            diags.push(bad(
                Code::ImplicitDensityAttribute,
                a.name_span,
                format!(
                    "{}= is given for an NRRD file, whose header sets it",
                    a.name
                ),
            ));
            return None;
        }
        let nrrd = parse_nrrd(&head).map_err(|(line, m)| {
            diags.push(bad(
                Code::ImplicitNrrdHeader,
                file.value_span,
                format!("{}:{line}: {m}", file.value.trim()),
            ))
        });
        let nrrd = nrrd.ok()?;
        match &nrrd.data_file {
            Some(name) => {
                let base = path.parent().unwrap_or(Path::new("."));
                let data = paths::resolve_in(env, base, name, file)
                    .map_err(|d| diags.push(d))
                    .ok()?;
                (nrrd.layout, data, 0)
            }
            None => (nrrd.layout, path.clone(), nrrd.header_len as u64),
        }
    } else {
        (raw_layout(e, diags)?, path.clone(), 0)
    };
    let expected = layout
        .bytes()
        .filter(|&b| b / layout.ty.size() as u64 <= MAX_SAMPLES);
    let Some(expected) = expected else {
        diags.push(bad(
            Code::ImplicitDensityAttribute,
            file.value_span,
            format!(
                "{} x {} x {} samples exceed the limit of {MAX_SAMPLES}",
                layout.dims[0], layout.dims[1], layout.dims[2]
            ),
        ));
        return None;
    };
    let actual = std::fs::metadata(&data_path)
        .map_err(|err| diags.push(unreadable(err)))
        .ok()?
        .len()
        .saturating_sub(offset);
    if actual != expected {
        diags.push(
            bad(
                Code::ImplicitFileSize,
                file.value_span,
                format!(
                    "'{}' holds {actual} bytes of samples; {} x {} x {} samples of {} need {expected}",
                    file.value.trim(),
                    layout.dims[0],
                    layout.dims[1],
                    layout.dims[2],
                    layout.ty.name()
                ),
            )
            .with_help("check dims and type against the file"),
        );
        return None;
    }
    let bytes = std::fs::read(&data_path)
        .map_err(|err| diags.push(unreadable(err)))
        .ok()?;
    let start = offset as usize;
    let data = bytes.get(start..start + expected as usize)?;
    Some((layout.grid(), decode(data, &layout, level)))
}
