//! Box caps (issue 5): where a solid leaves its grid's box, the polygonizer
//! closes it on the box face. Those triangles are not on the solid's
//! surface, so they get a face and fragment of their own (`NAME_box_cap`,
//! `NAME|box`; docs/format.md) and a solver can tell the cut from the
//! boundary.

/// Triangles split into (on the surface, on the box): a cap triangle has its
/// three nodes on one face plane of the box [min, max] (within 1e-9 of the
/// box's size).
pub fn split_caps(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    min: [f64; 3],
    max: [f64; 3],
) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let size = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
    let tol = 1e-9 * size.max(f64::MIN_POSITIVE);
    let on_plane = |t: &[u32; 3], axis: usize, value: f64| {
        t.iter().all(|&v| {
            positions
                .get(v as usize)
                .is_some_and(|p| (p[axis] - value).abs() <= tol)
        })
    };
    let is_cap = |t: &[u32; 3]| (0..3).any(|a| on_plane(t, a, min[a]) || on_plane(t, a, max[a]));
    triangles.iter().partition(|t| !is_cap(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_triangles_flat_on_one_box_face_are_caps() {
        let p = [
            [1.0, 0.0, 0.0],
            [1.0, 0.5, 0.0],
            [1.0, 0.0, 0.5],
            [0.9, 0.5, 0.5],
            [0.0, 1.0, 0.0],
        ];
        // On x = 1; touching x = 1 with one node off it; on x = 1 and y = 1
        // at one node only each.
        let t = [[0, 1, 2], [0, 1, 3], [1, 2, 4]];
        let (rest, caps) = split_caps(&p, &t, [-1.0; 3], [1.0; 3]);
        assert_eq!(caps, vec![[0, 1, 2]]);
        assert_eq!(rest, vec![[0, 1, 3], [1, 2, 4]]);
    }
}
