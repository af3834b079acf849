//! Paper 001's `Geom` fields as XML attributes (`x_min` … `z_max`, `nx`
//! `ny` `nz`, `optiterations`, `dimension`, `rsystem`, `alpha`), evaluated as
//! constants over the file's parameters.

use super::Env;
use super::tree::Lowerer;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::implicit::Geom;
use crate::implicit::rfs::RSystem;
use crate::syntax::Element;
use std::collections::BTreeSet;

/// Most grid samples of one solid (2²⁷, about 512³: 1 GiB of f64 values).
pub const MAX_SAMPLES: usize = 1 << 27;

/// A constant attribute: `None` when absent, `Some(None)` when bad (reported).
pub fn constant(
    e: &Element,
    attr: &str,
    env: &Env,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<Option<f64>> {
    let a = e.attribute(attr)?;
    let mut lw = Lowerer::new(env, None);
    let value = lw.attr_expr(a, &Default::default(), diags);
    used.extend(lw.used);
    let value = value.map(|id| lw.ctx.const_value(id));
    Some(match value {
        Some(Some(v)) if v.is_finite() => Some(v),
        Some(_) => {
            diags.push(Diagnostic::new(
                Code::ImplicitBadSetting,
                a.value_span,
                format!(
                    "{attr}=\"{}\" must be a finite constant (x, y, z have no value here)",
                    a.value
                ),
            ));
            None
        }
        None => None,
    })
}

/// Reads the Geom attributes of an `<rfunction>` or `<level_surface>`; `None`
/// when one is bad (reported).
pub fn geom(
    e: &Element,
    env: &Env,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<Geom> {
    let mut geom = Geom::default();
    let mut ok = true;
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        for (end, bound) in ["min", "max"].iter().enumerate() {
            match constant(e, &format!("{name}_{bound}"), env, used, diags) {
                Some(Some(v)) if end == 0 => geom.min[axis] = v,
                Some(Some(v)) => geom.max[axis] = v,
                Some(None) => ok = false,
                None => {}
            }
        }
        if geom.min[axis] >= geom.max[axis] {
            let span = e
                .attribute(&format!("{name}_max"))
                .or_else(|| e.attribute(&format!("{name}_min")))
                .map_or(e.name_span, |a| a.value_span);
            diags.push(Diagnostic::new(
                Code::ImplicitBadSetting,
                span,
                format!(
                    "{name}_min = {} is not below {name}_max = {}",
                    geom.min[axis], geom.max[axis]
                ),
            ));
            ok = false;
        }
        let cells = format!("n{name}");
        match constant(e, &cells, env, used, diags) {
            Some(Some(v)) if v.fract() == 0.0 && (1.0..=1024.0).contains(&v) => {
                geom.cells[axis] = v as usize;
            }
            Some(Some(v)) => {
                let span = e.attribute(&cells).map(|a| a.value_span);
                diags.push(Diagnostic::new(
                    Code::ImplicitBadSetting,
                    span,
                    format!("{cells} = {v}: give a whole number of cells from 1 to 1024"),
                ));
                ok = false;
            }
            Some(None) => ok = false,
            None => {}
        }
    }
    let samples: usize = geom.cells.iter().map(|n| n + 1).product();
    if samples > MAX_SAMPLES {
        diags.push(Diagnostic::new(
            Code::ImplicitBadSetting,
            e.attribute("nx").map_or(e.name_span, |a| a.value_span),
            format!(
                "{} x {} x {} cells need {samples} samples, over the limit of {MAX_SAMPLES}",
                geom.cells[0], geom.cells[1], geom.cells[2]
            ),
        ));
        ok = false;
    }
    match constant(e, "optiterations", env, used, diags) {
        Some(Some(v)) if v.fract() == 0.0 && (0.0..=1000.0).contains(&v) => {
            geom.optiterations = v as u32;
            // Applied by `ImplicitModel::polygonize` (W131 is retired).
            geom.optiterations_span = e.attribute("optiterations").map(|a| a.value_span);
        }
        Some(Some(v)) => {
            let span = e.attribute("optiterations").map(|a| a.value_span);
            diags.push(Diagnostic::new(
                Code::ImplicitBadSetting,
                span,
                format!("optiterations = {v}: give a whole number from 0 to 1000"),
            ));
            ok = false;
        }
        Some(None) => ok = false,
        None => {}
    }
    let alpha = constant(e, "alpha", env, used, diags);
    geom.rsystem = match (e.attribute("rsystem").map(|a| a.value.trim()), alpha) {
        (_, Some(None)) => {
            ok = false;
            RSystem::Rvachev
        }
        (Some("minmax"), _) => RSystem::MinMax,
        (Some("alpha"), a) | (None, a @ Some(_)) => RSystem::Alpha(a.flatten().unwrap_or(0.0)),
        _ => RSystem::Rvachev,
    };
    if !geom.rsystem.is_valid() {
        let span = e.attribute("alpha").map(|a| a.value_span);
        diags.push(Diagnostic::new(
            Code::ImplicitBadSetting,
            span,
            format!("alpha = {}: give a value in (-1, 1]", geom.rsystem.alpha()),
        ));
        ok = false;
    }
    geom.name = e
        .attribute("name")
        .map(|a| (a.value.trim().to_string(), a.value_span));
    ok.then_some(geom)
}
