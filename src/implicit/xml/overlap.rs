//! Implicit subdomains must not overlap, like all subdomains (E407): each pair
//! of function solids is sampled on a grid over the common part of their boxes,
//! and a point strictly inside both is reported. Sound (a reported point is in
//! both) but not complete: an overlap thinner than the sampling can pass.

use super::{ImplicitSolid, ImplicitSubdomain};
use crate::diag::{Code, Diagnostic, Diagnostics};

/// Samples per axis of the common box.
const SAMPLES: usize = 24;

pub fn check(subdomains: &[ImplicitSubdomain], diags: &mut Diagnostics) {
    let functions: Vec<(usize, &crate::implicit::ImplicitModel)> = subdomains
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match &s.solid {
            ImplicitSolid::Function(m) => Some((i, m)),
            ImplicitSolid::Samples { .. } => None,
        })
        .collect();
    let tapes: Vec<_> = functions.iter().map(|(_, m)| m.ssa()).collect();
    for a in 0..functions.len() {
        for b in a + 1..functions.len() {
            let (ga, gb) = (&functions[a].1.geom, &functions[b].1.geom);
            let lo: [f64; 3] = std::array::from_fn(|k| ga.min[k].max(gb.min[k]));
            let hi: [f64; 3] = std::array::from_fn(|k| ga.max[k].min(gb.max[k]));
            if (0..3).any(|k| lo[k] >= hi[k]) {
                continue;
            }
            let found = (0..SAMPLES.pow(3)).find_map(|n| {
                let idx = [
                    n % SAMPLES,
                    (n / SAMPLES) % SAMPLES,
                    n / (SAMPLES * SAMPLES),
                ];
                let p: [f64; 3] = std::array::from_fn(|k| {
                    lo[k] + (hi[k] - lo[k]) * (idx[k] as f64 + 0.5) / SAMPLES as f64
                });
                (tapes[a].eval_point(p) > 0.0 && tapes[b].eval_point(p) > 0.0).then_some(p)
            });
            if let Some(p) = found {
                let (first, second) = (&subdomains[functions[a].0], &subdomains[functions[b].0]);
                diags.push(
                    Diagnostic::new(
                        Code::SubdomainsOverlap,
                        second.span,
                        format!(
                            "subdomains '{}' and '{}' overlap: ({:.4}, {:.4}, {:.4}) is inside both",
                            first.name, second.name, p[0], p[1], p[2]
                        ),
                    )
                    .with_help(format!(
                        "carve one out of the other: <difference> <solid ref=\"…\"/> <solid ref=\"…\"/> </difference> in '{}'",
                        second.name
                    )),
                );
            }
        }
    }
}
