//! Meshing errors as diagnostics: a stable code, and the span of the face or
//! edge's defining element when the source map knows it.

use super::MeshError;
use crate::diag::{Code, Diagnostic};
use crate::ir::{EdgeId, FaceId, Model, SourceMap};

impl MeshError {
    pub fn code(&self) -> Code {
        match self {
            MeshError::Options(_) => Code::InvalidMeshOption,
            MeshError::Edge { .. } => Code::EdgeNotDiscretisable,
            MeshError::Face { .. } => Code::FaceNotMeshable,
            MeshError::Internal { .. } => Code::InternalMeshingFailure,
        }
    }

    /// The error as a diagnostic pointing at the entity's definition.
    pub fn to_diagnostic(&self, model: &Model, source_map: &SourceMap) -> Diagnostic {
        let face_span = |name: &str| {
            let id = model.faces.iter().position(|f| f.name == name)?;
            source_map.face(FaceId(id as u32))
        };
        let edge_span = |name: &str| {
            let id = model.edges.iter().position(|e| e.name == name)?;
            source_map.edge(EdgeId(id as u32))
        };
        let span = match self {
            MeshError::Options(_) => None,
            MeshError::Edge { edge, .. } => edge_span(edge),
            MeshError::Face { face, .. } => face_span(face),
            MeshError::Internal { entity, .. } => {
                // `entity` reads "face `NAME`" or "edge `NAME`".
                let name = entity.split('`').nth(1).unwrap_or_default();
                if entity.starts_with("face") {
                    face_span(name)
                } else {
                    edge_span(name)
                }
            }
        };
        let diagnostic = Diagnostic::new(self.code(), span, self.to_string());
        match self {
            MeshError::Internal { .. } => diagnostic.with_help(
                "this is a bug in geomc: please report it with this input; a slightly different --tolerance or --max-edge may avoid it",
            ),
            MeshError::Options(_) => diagnostic.with_help(
                "give --tolerance as a positive length (0.01) or percentage (0.1%), --max-edge as a positive length",
            ),
            MeshError::Edge { .. } | MeshError::Face { .. } => diagnostic
                .with_help("loosen --tolerance or --max-edge, or check the entity's definition"),
        }
    }
}
