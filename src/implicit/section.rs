//! Contour lines of a plane cut (`--section z=0`) of a polygonized surface:
//! each triangle crossing the plane gives a segment between the crossings of
//! two of its edges; crossings are keyed by their mesh edge, so neighbouring
//! triangles share them and segments chain into polylines (closed loops for a
//! closed surface). A vertex exactly on the plane counts as above it, so every
//! crossing lies strictly inside an edge.

use std::collections::BTreeMap;

/// The polylines of {p[axis] = value} on the triangles, in a deterministic
/// order; a closed loop repeats its first point at the end.
pub fn contours(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    axis: usize,
    value: f64,
) -> Vec<Vec<[f64; 3]>> {
    let above = |i: u32| positions[i as usize][axis] >= value;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // Segments between edge keys; each key meets at most two segments on a manifold surface.
    let mut segments: Vec<[(u32, u32); 2]> = Vec::new();
    for t in triangles {
        let crossed: Vec<(u32, u32)> = (0..3)
            .map(|k| (t[k], t[(k + 1) % 3]))
            .filter(|&(a, b)| above(a) != above(b))
            .map(|(a, b)| key(a, b))
            .collect();
        if let [a, b] = crossed[..] {
            segments.push([a, b]);
        }
    }
    let mut at: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
    for (i, s) in segments.iter().enumerate() {
        at.entry(s[0]).or_default().push(i);
        at.entry(s[1]).or_default().push(i);
    }
    let point = |(a, b): (u32, u32)| {
        let (p, q) = (positions[a as usize], positions[b as usize]);
        let t = (value - p[axis]) / (q[axis] - p[axis]);
        let mut out = [0.0; 3];
        for c in 0..3 {
            out[c] = p[c] + t * (q[c] - p[c]);
        }
        out[axis] = value;
        out
    };
    let mut done = vec![false; segments.len()];
    let mut out = Vec::new();
    // Open chains start at keys with one segment; then the remaining loops.
    let starts: Vec<(u32, u32)> = at
        .iter()
        .filter(|(_, s)| s.len() == 1)
        .map(|(k, _)| *k)
        .chain(at.keys().copied())
        .collect();
    for start in starts {
        let Some(&first) = at[&start].iter().find(|&&s| !done[s]) else {
            continue;
        };
        let mut keys = vec![start];
        let mut seg = first;
        let mut here = start;
        loop {
            done[seg] = true;
            let next = if segments[seg][0] == here {
                segments[seg][1]
            } else {
                segments[seg][0]
            };
            keys.push(next);
            here = next;
            match at[&here].iter().find(|&&s| !done[s]) {
                Some(&s) => seg = s,
                None => break,
            }
        }
        out.push(keys.into_iter().map(point).collect());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_octahedron_cut_at_its_equator_plane_gives_one_closed_square() {
        let p = vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = vec![
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
            [1, 0, 5],
            [2, 1, 5],
            [3, 2, 5],
            [0, 3, 5],
        ];
        let lines = contours(&p, &t, 2, 0.5);
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].len(), 5, "four corners and the closing point");
        assert_eq!(lines[0][0], lines[0][4]);
        for q in &lines[0] {
            assert!((q[2] - 0.5).abs() < 1e-15);
            assert!((q[0].abs() + q[1].abs() - 0.5).abs() < 1e-12);
        }
        assert!(contours(&p, &t, 2, 2.0).is_empty());
    }
}
