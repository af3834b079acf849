//! Data files named by the XML: resolved against the XML file's folder, and
//! refused when they lead outside it (or outside an `--allow-path` folder), so
//! a model cannot make geomc read arbitrary files.

use super::Env;
use crate::diag::{Code, Diagnostic};
use crate::syntax::Attribute;
use std::path::{Path, PathBuf};

/// The file an attribute names, canonical, or the diagnostic (E618, E619).
pub fn resolve(env: &Env, attr: &Attribute) -> Result<PathBuf, Diagnostic> {
    resolve_in(env, &env.folder, attr.value.trim(), attr)
}

/// `relative` resolved against `base` (a header's folder for detached data).
pub fn resolve_in(
    env: &Env,
    base: &Path,
    relative: &str,
    attr: &Attribute,
) -> Result<PathBuf, Diagnostic> {
    let joined = base.join(relative);
    let canonical = joined.canonicalize().map_err(|e| {
        Diagnostic::new(
            Code::ImplicitFileUnreadable,
            attr.value_span,
            format!("cannot read '{relative}' ({}): {e}", joined.display()),
        )
        .with_help("paths are relative to the XML file's folder")
    })?;
    let inside = |dir: &Path| dir.canonicalize().is_ok_and(|d| canonical.starts_with(d));
    if inside(&env.folder) || env.allowed.iter().any(|d| inside(d)) {
        Ok(canonical)
    } else {
        Err(Diagnostic::new(
            Code::ImplicitPathRefused,
            attr.value_span,
            format!(
                "'{relative}' leads outside the input's folder {}",
                env.folder.display()
            ),
        )
        .with_help("move the file next to the model, or pass --allow-path DIR for its folder"))
    }
}
