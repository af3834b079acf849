//! The side table from IR entities back to the XML that defined them, so the
//! validator can point at the source without the IR carrying spans.

use super::{EdgeId, FaceId, SolidId, SubdomainId, VertexId};
use crate::span::Span;
use std::collections::HashMap;

/// Where an entity came from: the span of the defining element's name (or the
/// whole element) in the source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    pub span: Span,
}

#[derive(Debug, Clone, Default)]
pub struct SourceMap {
    pub vertices: HashMap<VertexId, Origin>,
    pub edges: HashMap<EdgeId, Origin>,
    pub faces: HashMap<FaceId, Origin>,
    pub subdomains: HashMap<SubdomainId, Origin>,
    pub solids: HashMap<SolidId, Origin>,
}

impl SourceMap {
    pub fn vertex(&self, id: VertexId) -> Option<Span> {
        self.vertices.get(&id).map(|o| o.span)
    }
    pub fn edge(&self, id: EdgeId) -> Option<Span> {
        self.edges.get(&id).map(|o| o.span)
    }
    pub fn face(&self, id: FaceId) -> Option<Span> {
        self.faces.get(&id).map(|o| o.span)
    }
    pub fn subdomain(&self, id: SubdomainId) -> Option<Span> {
        self.subdomains.get(&id).map(|o| o.span)
    }
    pub fn solid(&self, id: SolidId) -> Option<Span> {
        self.solids.get(&id).map(|o| o.span)
    }
}
