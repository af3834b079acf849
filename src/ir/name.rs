//! Entity names without a string per entity. The entities of a primitive
//! solid are named "{solid}.{local}" ("box.xmin", "poly.v3"): they share the
//! solid's name (one allocation per solid) and keep only a small code for the
//! local part. On files of many primitives a `String` per vertex, edge and
//! face was a tenth of the model's memory.

use std::fmt;
use std::sync::Arc;

/// The local part of a primitive's entity name: a documented name from
/// [`LOCAL_NAMES`], or a polygon's numbered vertex or edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LocalName {
    /// An index into [`LOCAL_NAMES`].
    Named(u16),
    /// "v{n}", counted from 1.
    Vertex(u32),
    /// "e{n}", counted from 1.
    Edge(u32),
}

/// Every documented local name of the primitives' entities (`lower/brep.rs`
/// indexes this table; `docs/format.md` lists the names per primitive).
pub const LOCAL_NAMES: [&str; 42] = [
    // Parallelepiped faces, by axis then side (0..6).
    "xmin",
    "xmax",
    "ymin",
    "ymax",
    "zmin",
    "zmax",
    // Parallelepiped edges, by the axis they run along, then the sides of the
    // other two axes in ascending axis order (6..18).
    "ymin_zmin",
    "ymin_zmax",
    "ymax_zmin",
    "ymax_zmax",
    "xmin_zmin",
    "xmin_zmax",
    "xmax_zmin",
    "xmax_zmax",
    "xmin_ymin",
    "xmin_ymax",
    "xmax_ymin",
    "xmax_ymax",
    // Parallelepiped vertices v{x}{y}{z} (18..26).
    "v000",
    "v100",
    "v010",
    "v110",
    "v001",
    "v101",
    "v011",
    "v111",
    // The round primitives (26..).
    "seam",
    "equator",
    "north",
    "south",
    "bottom_seam",
    "bottom_rim",
    "bottom",
    "top_seam",
    "top_rim",
    "top",
    "side",
    "parallel",
    "meridian",
    "surface",
    "rim",
    "region",
];

impl LocalName {
    /// The entry of [`LOCAL_NAMES`] spelled `name`; evaluated at compile time
    /// where `brep.rs` names its constants (an unknown name fails the build).
    pub const fn named(name: &str) -> LocalName {
        let mut i = 0;
        while i < LOCAL_NAMES.len() {
            if const_eq(LOCAL_NAMES[i], name) {
                return LocalName::Named(i as u16);
            }
            i += 1;
        }
        panic!("not a local name of LOCAL_NAMES")
    }

    /// The packed form stored in an [`EntityName`].
    fn code(self) -> u32 {
        match self {
            LocalName::Named(i) => i as u32,
            LocalName::Vertex(n) => VERTEX_TAG | (n & INDEX_MASK),
            LocalName::Edge(n) => EDGE_TAG | (n & INDEX_MASK),
        }
    }

    fn from_code(code: u32) -> LocalName {
        match code & TAG_MASK {
            VERTEX_TAG => LocalName::Vertex(code & INDEX_MASK),
            EDGE_TAG => LocalName::Edge(code & INDEX_MASK),
            _ => LocalName::Named(code as u16),
        }
    }
}

impl fmt::Display for LocalName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LocalName::Named(i) => f.write_str(LOCAL_NAMES.get(i as usize).copied().unwrap_or("?")),
            LocalName::Vertex(n) => write!(f, "v{n}"),
            LocalName::Edge(n) => write!(f, "e{n}"),
        }
    }
}

const fn const_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const TAG_MASK: u32 = 0xC000_0000;
const VERTEX_TAG: u32 = 0x4000_0000;
const EDGE_TAG: u32 = 0x8000_0000;
const INDEX_MASK: u32 = !TAG_MASK;
/// No local part: the base is the whole name.
const WHOLE: u32 = u32::MAX;

/// The name of a vertex, edge or face: a shared base (the solid's name, or a
/// whole given name) and an optional local part. 16 bytes, no allocation of
/// its own when it names a primitive's entity. Displays as the full name;
/// compare it with a `&str` through `==`.
#[derive(Clone)]
pub struct EntityName {
    base: Arc<Box<str>>,
    local: u32,
}

impl EntityName {
    /// A whole name (explicit entities, test models).
    pub fn whole(name: &str) -> EntityName {
        EntityName {
            base: Arc::new(name.into()),
            local: WHOLE,
        }
    }

    /// "{solid}.{local}", sharing `solid` with the solid's other entities.
    pub fn local(solid: &Arc<Box<str>>, local: LocalName) -> EntityName {
        EntityName {
            base: Arc::clone(solid),
            local: local.code(),
        }
    }

    /// The local part, if the name has one.
    fn local_part(&self) -> Option<LocalName> {
        (self.local != WHOLE).then(|| LocalName::from_code(self.local))
    }

    /// Whether the name is spelled `s`, without building the string (the
    /// local part is compared by formatting it into a small buffer).
    fn eq_str(&self, s: &str) -> bool {
        let base: &str = &self.base;
        let Some(local) = self.local_part() else {
            return base == s;
        };
        let Some(rest) = s.strip_prefix(base).and_then(|r| r.strip_prefix('.')) else {
            return false;
        };
        match local {
            LocalName::Named(i) => LOCAL_NAMES.get(i as usize) == Some(&rest),
            LocalName::Vertex(n) => rest.strip_prefix('v') == Some(&n.to_string()),
            LocalName::Edge(n) => rest.strip_prefix('e') == Some(&n.to_string()),
        }
    }
}

impl fmt::Display for EntityName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.local_part() {
            None => f.write_str(&self.base),
            Some(local) => write!(f, "{}.{local}", self.base),
        }
    }
}

impl fmt::Debug for EntityName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.to_string(), f)
    }
}

impl PartialEq for EntityName {
    fn eq(&self, other: &EntityName) -> bool {
        if self.local == other.local && Arc::ptr_eq(&self.base, &other.base) {
            return true;
        }
        self.eq_str(&other.to_string())
    }
}

impl PartialEq<str> for EntityName {
    fn eq(&self, other: &str) -> bool {
        self.eq_str(other)
    }
}

impl PartialEq<&str> for EntityName {
    fn eq(&self, other: &&str) -> bool {
        self.eq_str(other)
    }
}

impl PartialEq<String> for EntityName {
    fn eq(&self, other: &String) -> bool {
        self.eq_str(other)
    }
}

impl From<&str> for EntityName {
    fn from(name: &str) -> EntityName {
        EntityName::whole(name)
    }
}

impl From<String> for EntityName {
    fn from(name: String) -> EntityName {
        EntityName {
            base: Arc::new(name.into_boxed_str()),
            local: WHOLE,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_display_and_compare_as_their_full_spelling() {
        let solid: Arc<Box<str>> = Arc::new("box".into());
        let xmin = EntityName::local(&solid, LocalName::named("xmin"));
        assert_eq!(xmin.to_string(), "box.xmin");
        assert!(xmin == "box.xmin" && xmin != "box.xmax" && xmin != "box" && xmin != "bo.xmin");
        let v12 = EntityName::local(&solid, LocalName::Vertex(12));
        assert_eq!(v12.to_string(), "box.v12");
        assert!(v12 == "box.v12" && v12 != "box.v1" && v12 != "box.e12");
        let e3 = EntityName::local(&solid, LocalName::Edge(3));
        assert_eq!(format!("{e3:?}"), "\"box.e3\"");
        assert_eq!(EntityName::from("box.e3"), e3);
        let face = EntityName::from("face");
        assert!(face == "face" && face != "face.x" && face != "fac");
        assert_eq!(std::mem::size_of::<EntityName>(), 16);
    }

    #[test]
    fn every_local_name_is_listed_once() {
        for (i, name) in LOCAL_NAMES.iter().enumerate() {
            assert_eq!(LocalName::named(name), LocalName::Named(i as u16), "{name}");
        }
    }
}
