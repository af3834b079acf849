//! Cutting a kernel edge into parts where a 2D region's contour shares some of
//! it (box sides on a straight edge, contour runs on an arc): the first part
//! keeps the edge's id, name and boundaries, so everything that named the edge
//! still finds it; the n-th part is a new edge `NAME.n` with the edge's source
//! position, added to every `<boundary>` group that named the edge.

use crate::geom::Curve;
use crate::ir::{Carrier, Edge, EdgeId, EntityName, Model, SourceMap, VertexId};

pub(super) struct EdgeParts {
    edge: EdgeId,
    name: EntityName,
    added: Vec<EdgeId>,
    count: usize,
}

impl EdgeParts {
    pub(super) fn new(model: &Model, edge: EdgeId) -> EdgeParts {
        EdgeParts {
            edge,
            name: model.edge(edge).name.clone(),
            added: Vec::new(),
            count: 0,
        }
    }

    /// The next part, `curve` from `begin` to `end`, in the edge's direction.
    pub(super) fn push(
        &mut self,
        model: &mut Model,
        source_map: &mut SourceMap,
        curve: Curve,
        begin: VertexId,
        end: VertexId,
    ) -> EdgeId {
        self.count += 1;
        if self.count == 1 {
            let edge = &mut model.edges[self.edge.index()];
            (edge.carrier, edge.begin, edge.end) = (Carrier::own(curve), begin, end);
            return self.edge;
        }
        let id = EdgeId(model.edges.len() as u32);
        model.edges.push(Edge {
            name: format!("{}.{}", self.name, self.count).into(),
            carrier: Carrier::own(curve),
            begin,
            end,
        });
        if let Some(&origin) = source_map.edges.get(&self.edge) {
            source_map.edges.insert(id, origin);
        }
        self.added.push(id);
        id
    }

    /// Adds the new parts to the boundary groups that named the edge.
    pub(super) fn finish(self, model: &mut Model) {
        for boundary in &mut model.boundaries {
            if boundary.edges.contains(&self.edge) {
                boundary.edges.extend(self.added.iter().copied());
            }
        }
    }
}

/// A straight or contour piece's curve ends where its vertices are again,
/// after a vertex was merged into another or moved onto a kernel edge.
pub(super) fn follow_vertices(model: &mut Model, e: EdgeId) {
    let edge = model.edge(e);
    let (pa, pb) = (
        model.vertex(edge.begin).position,
        model.vertex(edge.end).position,
    );
    if let Curve::Segment { a, b } | Curve::Contour { a, b, .. } = model.edge_curve_mut(e) {
        (*a, *b) = (pa, pb);
    }
}
