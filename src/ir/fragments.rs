//! Boundary fragments Γ_{k,k'} derived from M_FD: faces (edges, in 2D)
//! between two subdomains are interface fragments, faces of one subdomain only
//! belong to its outer boundary Γ_{k,0}.

use super::{EdgeId, FaceId, Model, SubdomainId};

/// The other side of a fragment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Side {
    Exterior,
    Subdomain(SubdomainId),
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Fragment {
    /// The user's <boundary> name when one names these faces, else
    /// "A|B" from the subdomain names ("A|exterior" for the outer boundary).
    pub name: String,
    /// The subdomain on the side the faces' normals point away from... the
    /// lower-numbered subdomain of the pair (k < k'), and the other side.
    pub subdomain: SubdomainId,
    pub other: Side,
    /// Faces of the fragment (3D), sorted.
    pub faces: Vec<FaceId>,
    /// Edges of the fragment (2D), sorted.
    pub edges: Vec<EdgeId>,
}

/// Fragments grouped by (subdomain pair, boundary name), ordered by subdomain,
/// then other side, then name: deterministic for the same model.
pub fn derive_fragments(model: &Model) -> Vec<Fragment> {
    let _ = model;
    todo!("topology")
}
