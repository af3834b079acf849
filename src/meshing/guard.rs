//! The panic guard: each edge and face is meshed under `catch_unwind`, so a
//! bug (or a panic inside spade) becomes an error naming the entity, not a
//! crash that loses every other input of a parallel run.

use super::MeshError;
use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};

thread_local! {
    /// How many guards are active on this thread.
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// True while the current thread runs under a meshing guard: a panic hook
/// can then stay quiet, since the panic becomes an error diagnostic.
pub fn panics_are_caught() -> bool {
    DEPTH.with(|d| d.get() > 0)
}

/// Runs `work`; a panic in it becomes [`MeshError::Internal`] for the entity
/// `entity()` names.
pub(crate) fn guarded<T>(
    entity: impl FnOnce() -> String,
    work: impl FnOnce() -> Result<T, MeshError>,
) -> Result<T, MeshError> {
    DEPTH.with(|d| d.set(d.get() + 1));
    // The work only reads shared state, so nothing is left half-modified.
    let result = catch_unwind(AssertUnwindSafe(work));
    DEPTH.with(|d| d.set(d.get().saturating_sub(1)));
    result.unwrap_or_else(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".to_string());
        Err(MeshError::Internal {
            entity: entity(),
            message,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_an_internal_error_naming_the_entity() {
        let result: Result<(), MeshError> = guarded(
            || "face `ball.north`".to_string(),
            || {
                assert!(panics_are_caught());
                panic!("precision loss at {}", 42)
            },
        );
        assert_eq!(
            result,
            Err(MeshError::Internal {
                entity: "face `ball.north`".into(),
                message: "precision loss at 42".into(),
            })
        );
        assert!(!panics_are_caught());
        assert_eq!(
            result.unwrap_err().to_string(),
            "internal meshing failure on face `ball.north`: precision loss at 42"
        );
    }

    #[test]
    fn errors_and_values_pass_through() {
        assert_eq!(guarded(|| "x".into(), || Ok(7)), Ok(7));
        let err = MeshError::Options("bad".into());
        assert_eq!(guarded::<()>(|| "x".into(), || Err(err.clone())), Err(err));
    }
}
