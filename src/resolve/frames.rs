//! Coordinate systems: each resolves to a rigid frame, through its parents.

use crate::diag::{did_you_mean, Code, Diagnostic, Diagnostics};
use crate::doc::{CoordinateSystem, Ref};
use crate::geom::{Frame, Vec3};
use std::collections::HashMap;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum FrameState {
    InProgress,
    Done(Option<Frame>),
}

/// Evaluates a coordinate system's origin and rotation angles in its parent's frame.
pub(super) type EvalFrame<'a> = dyn FnMut(&CoordinateSystem, &mut Diagnostics) -> Option<(Vec3, Vec3)> + 'a;

/// Resolves coordinate system `name`; `eval` evaluates its origin and rotation
/// in the parent's frame.
pub(super) fn resolve_cs(
    reference: &Ref,
    systems: &HashMap<String, &CoordinateSystem>,
    state: &mut HashMap<String, FrameState>,
    other_kind: Option<&str>,
    eval: &mut EvalFrame,
    diags: &mut Diagnostics,
) -> Option<Frame> {
    let name = reference.name.as_str();
    let Some(cs) = systems.get(name) else {
        let d = match other_kind {
            Some(kind) => Diagnostic::new(
                Code::WrongKind,
                reference.span,
                format!("cs=\"{name}\" names a {kind}, not a coordinate system"),
            )
            .with_help("name a <coordinate_system>"),
            None => {
                let mut d = Diagnostic::new(
                    Code::UndefinedName,
                    reference.span,
                    format!("undefined coordinate system '{name}'"),
                );
                d.help = Some(match did_you_mean(name, systems.keys().map(String::as_str)) {
                    Some(best) => format!("did you mean '{best}'?"),
                    None => format!("define it with <coordinate_system name=\"{name}\">"),
                });
                d
            }
        };
        diags.push(d);
        return None;
    };
    match state.get(name) {
        Some(FrameState::Done(frame)) => return *frame,
        Some(FrameState::InProgress) => {
            diags.push(
                Diagnostic::new(
                    Code::ReferenceCycle,
                    cs.name.span,
                    format!("coordinate system '{name}' lies inside itself through its cs= chain"),
                )
                .with_help("remove cs= from one of the systems in the chain"),
            );
            state.insert(name.to_string(), FrameState::Done(None));
            return None;
        }
        None => {}
    }
    state.insert(name.to_string(), FrameState::InProgress);
    let parent = match &cs.parent {
        Some(p) => resolve_cs(p, systems, state, None, eval, diags),
        None => Some(Frame::identity()),
    };
    if let Some(FrameState::Done(None)) = state.get(name) {
        return None;
    }
    let local = eval(cs, diags).map(|(origin, angles)| {
        let rotation = Frame::rotation_degrees(angles);
        Frame::translation(origin).compose(&rotation)
    });
    let frame = match (parent, local) {
        (Some(parent), Some(local)) => Some(parent.compose(&local)),
        _ => None,
    };
    state.insert(name.to_string(), FrameState::Done(frame));
    frame
}
