//! A straight trim edge that crosses a periodic seam at a right angle (the
//! interstage fixture's bottom edge at y = 0.65, issue 9): no input angle
//! there, so no triangle may stay below the threshold.

use super::tests::{below_threshold, check_manifold, interstage_cone};
use super::*;
use crate::implicit::ir::{Binary, Ctx};

/// The interstage cone with one rectangular cut-out |z| < 0.3,
/// |y − 1| < 0.35 on the side x > 0, centred on the seam v = 0: material
/// where F = min(0.3² − z², 0.35² − (y − 1)², x) ≤ 0.
fn cone_with_seam_cut_out() -> TrimmedSurface {
    let mut c = Ctx::new();
    let (x, y, z) = (c.var(0), c.var(1), c.var(2));
    let z2 = c.square(z);
    let w = c.constant(0.09);
    let across = c.sub(w, z2);
    let one = c.constant(1.0);
    let dy = c.sub(y, one);
    let dy2 = c.square(dy);
    let h = c.constant(0.35 * 0.35);
    let along = c.sub(h, dy2);
    let rect = c.binary(Binary::Min, across, along);
    let f = c.binary(Binary::Min, rect, x);
    interstage_cone(Some(Trim::new(&c, f, true)))
}

#[test]
fn straight_trim_edge_across_the_seam_keeps_the_min_angle() {
    let s = cone_with_seam_cut_out();
    let settings = TrimSettings {
        tolerance: 0.0002,
        min_angle: 20.0,
        max_edge: f64::INFINITY,
    };
    let m = mesh_trimmed(&s, settings).expect("meshable");
    check_manifold(&m);
    // Before the fix 18 triangles of 12–17° stayed at the corners where the
    // edge meets the seam (a circumcentre on a right triangle's hypotenuse
    // was tested against the neighbour's edges only).
    let q = m.quality(&s);
    assert_eq!(below_threshold(&m, settings.min_angle), (0, 0), "{q:?}");
    assert!(q.min_angle >= settings.min_angle, "{q:?}");
    assert!(q.max_centroid_distance <= settings.tolerance, "{q:?}");
}
