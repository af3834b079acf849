//! Nodes to sample space for the raster: each node's snapped x and y with its
//! depth normalised over the model's depth range, and its unsnapped x and y
//! for shading. Half a million nodes make the per-node instructions count,
//! so x and y are computed as the two lanes of one SSE2 vector: the same IEEE
//! operations in the same order as [`Camera::project`] followed by the
//! scalar scaling, clamping and snapping of [`scalar_node`], lane by lane
//! (nothing fused), so the same bits.

use super::camera::{Camera, above, below};
use super::raster::{Projected, Snapped};
use rayon::prelude::*;

/// Nodes per unit of parallel work.
const BLOCK: usize = 1 << 13;
/// Far outside the picture only the clamped bounding box matters.
const LIMIT: f64 = 1e6;

/// Node positions in sample space (`ss` samples per pixel along each axis),
/// depths normalised to [0, 1].
pub fn project(points: &[[f64; 3]], camera: &Camera, ss: usize) -> Projected {
    let (lo, hi) = depth_range(points, camera);
    let range = if hi > lo { hi - lo } else { 1.0 };
    let map = NodeMap {
        camera,
        ss: ss as f64,
        lo,
        range,
    };
    let n = points.len();
    let mut snapped: Vec<Snapped> = Vec::with_capacity(n);
    let mut xy_f: Vec<[f32; 2]> = Vec::with_capacity(n);
    (points.par_chunks(BLOCK))
        .zip(snapped.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
        .zip(xy_f.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
        .for_each(|((from, to_snapped), to_xy)| {
            for ((q, s), f) in from.iter().zip(to_snapped).zip(to_xy) {
                let (node, xy) = map.node(q);
                s.write(node);
                f.write(xy);
            }
        });
    // SAFETY: the chunks above cover the first `n` slots of both vectors
    // (`points`, `..n` of each spare capacity, one block size), and every
    // slot of them was written.
    unsafe {
        snapped.set_len(n);
        xy_f.set_len(n);
    }
    Projected { snapped, xy_f }
}

/// The least and greatest depth of the nodes ([`Camera::depth`]). Blocks
/// are folded in order and joined in block order with the same comparisons,
/// so the result is the serial fold's for any thread count.
fn depth_range(points: &[[f64; 3]], camera: &Camera) -> (f64, f64) {
    let blocks: Vec<(f64, f64)> = points
        .par_chunks(BLOCK)
        .map(|block| {
            block
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                    let z = camera.depth(*q);
                    (below(z, l), above(z, h))
                })
        })
        .collect();
    blocks
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (bl, bh)| {
            (below(bl, l), above(bh, h))
        })
}

/// What one node's projection needs.
struct NodeMap<'c> {
    camera: &'c Camera,
    ss: f64,
    lo: f64,
    range: f64,
}

impl NodeMap<'_> {
    /// The node's snapped position and normalised depth, and its unsnapped
    /// sample-space x and y.
    #[inline(always)]
    fn node(&self, q: &[f64; 3]) -> (Snapped, [f32; 2]) {
        #[cfg(target_arch = "x86_64")]
        {
            self.node_sse2(q)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            scalar_node(self.camera, self.ss, self.lo, self.range, *q)
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn node_sse2(&self, q: &[f64; 3]) -> (Snapped, [f32; 2]) {
        // SAFETY (every intrinsic below): SSE2 is part of every x86-64, and
        // none of them reads memory.
        unsafe { self.lanes(q) }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    #[inline]
    fn lanes(&self, q: &[f64; 3]) -> (Snapped, [f32; 2]) {
        use std::arch::x86_64::*;
        let c = self.camera;
        let d = [q[0] - c.center[0], q[1] - c.center[1], q[2] - c.center[2]];
        let z = -(d[0] * c.toward_eye[0] + d[1] * c.toward_eye[1] + d[2] * c.toward_eye[2]);
        let z = ((z - self.lo) / self.range) as f32;
        // Lanes (x, y): x = w/2 + s·(d·right), y = h/2 + (−s)·(d·up), which is
        // h/2 − s·(d·up) bit for bit (negation is exact).
        let lanes = |a: f64, b: f64| _mm_set_pd(b, a);
        let dots = _mm_add_pd(
            _mm_add_pd(
                _mm_mul_pd(_mm_set1_pd(d[0]), lanes(c.right[0], c.up[0])),
                _mm_mul_pd(_mm_set1_pd(d[1]), lanes(c.right[1], c.up[1])),
            ),
            _mm_mul_pd(_mm_set1_pd(d[2]), lanes(c.right[2], c.up[2])),
        );
        let image = _mm_add_pd(
            lanes(0.5 * c.width as f64, 0.5 * c.height as f64),
            _mm_mul_pd(lanes(c.scale, -c.scale), dots),
        );
        // `clamp`: `maxpd`/`minpd` return their second operand when either
        // is NaN, so a NaN stays NaN as `f64::clamp` keeps it.
        let v = _mm_min_pd(
            _mm_set1_pd(LIMIT),
            _mm_max_pd(_mm_set1_pd(-LIMIT), _mm_mul_pd(image, _mm_set1_pd(self.ss))),
        );
        let xy = _mm_cvtpd_ps(v);
        // `snap`: v·16 plus a half with v's sign, truncated; a NaN lane is
        // zeroed first, as `as i32` turns NaN into 0.
        let v16 = _mm_mul_pd(v, _mm_set1_pd(16.0));
        let half = _mm_or_pd(_mm_and_pd(v16, _mm_set1_pd(-0.0)), _mm_set1_pd(0.5));
        let rounded = _mm_add_pd(v16, half);
        let rounded = _mm_and_pd(rounded, _mm_cmpord_pd(rounded, rounded));
        let snapped = _mm_cvttpd_epi32(rounded);
        let xy_bits = _mm_cvtsi128_si64(_mm_castps_si128(xy)) as u64;
        let s_bits = _mm_cvtsi128_si64(snapped) as u64;
        (
            Snapped {
                x: s_bits as u32 as i32,
                y: (s_bits >> 32) as u32 as i32,
                z,
            },
            [
                f32::from_bits(xy_bits as u32),
                f32::from_bits((xy_bits >> 32) as u32),
            ],
        )
    }
}

/// One node as the scalar code computes it: the reference the vector lanes
/// follow (and the path off x86-64).
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn scalar_node(camera: &Camera, s: f64, lo: f64, range: f64, q: [f64; 3]) -> (Snapped, [f32; 2]) {
    let p = camera.project(q);
    let (x, y) = (
        (p[0] * s).clamp(-LIMIT, LIMIT),
        (p[1] * s).clamp(-LIMIT, LIMIT),
    );
    let z = ((p[2] - lo) / range) as f32;
    (
        Snapped {
            x: snap(x),
            y: snap(y),
            z,
        },
        [x as f32, y as f32],
    )
}

/// A sample-space coordinate in 1/16 sample steps, rounded half away from
/// zero (`f64::round` is a library call on baseline x86-64). `v` is within
/// ±1e6 samples, so the steps fit an `i32`.
#[inline]
fn snap(v: f64) -> i32 {
    let v = v * 16.0;
    (v + 0.5f64.copysign(v)) as i32
}

#[cfg(test)]
mod tests {
    use super::super::camera::View;
    use super::*;

    /// Points whose products round, far outside the picture, on the sample
    /// grid's halves, negative zeros and NaN.
    fn awkward_points() -> Vec<[f64; 3]> {
        let mut points: Vec<[f64; 3]> = (0..4000)
            .map(|i| {
                let t = i as f64 * 0.618_033_988_749_895;
                [
                    t.sin() * 1.3 + t.fract() * 1e-7,
                    (t * 1.7).cos() * 0.37,
                    (t * 0.3).sin() * 2.1 - 1e-9 * t,
                ]
            })
            .collect();
        points.extend([
            [1e9, -3e8, 2.0],
            [-1e12, 1e12, -5.0],
            [-0.0, -0.0, -0.0],
            [f64::NAN, 0.5, 0.25],
            [0.25, f64::NAN, 0.5],
            [0.5, 0.25, f64::NAN],
            [f64::INFINITY, 0.0, 0.0],
        ]);
        points
    }

    #[test]
    fn vector_lanes_project_as_the_scalar_code_bit_for_bit() {
        let points = awkward_points();
        let fitted = &points[..4000];
        for (view, ss, (w, h)) in [
            (View::ISO, 2, (1024, 1024)),
            (View::FRONT, 1, (333, 211)),
            (View::TOP, 3, (640, 480)),
            (
                View {
                    azimuth: 200.0,
                    elevation: -30.0,
                },
                4,
                (97, 1301),
            ),
        ] {
            let camera = Camera::fit(view, fitted, w, h);
            let proj = project(&points, &camera, ss);
            assert_eq!(proj.snapped.len(), points.len());
            let (lo, hi) = depth_range(&points, &camera);
            assert!(lo < hi);
            let range = hi - lo;
            let mut inside = 0;
            for (i, q) in points.iter().enumerate() {
                let (want, want_xy) = scalar_node(&camera, ss as f64, lo, range, *q);
                let got = proj.snapped[i];
                assert_eq!((got.x, got.y), (want.x, want.y), "node {i}");
                assert_eq!(got.z.to_bits(), want.z.to_bits(), "node {i}");
                assert_eq!(proj.xy_f[i].map(f32::to_bits), want_xy.map(f32::to_bits));
                let picture = (w * ss as u32 * 16) as i32;
                inside += usize::from((0..picture).contains(&got.x));
            }
            // The fitted points lie inside the picture, the far ones are clamped.
            assert!(inside >= 4000, "{inside}");
            assert_eq!(proj.snapped[4000].x.abs(), (LIMIT * 16.0) as i32);
            assert_eq!(proj.snapped[4004].y, 0, "NaN snaps to 0");
        }
    }

    #[test]
    fn depth_range_is_the_serial_fold() {
        let points = awkward_points();
        let camera = Camera::fit(View::ISO, &points[..4000], 800, 600);
        let serial = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                let z = camera.depth(*q);
                (below(z, l), above(z, h))
            });
        let got = depth_range(&points, &camera);
        assert_eq!(
            (got.0.to_bits(), got.1.to_bits()),
            (serial.0.to_bits(), serial.1.to_bits())
        );
    }
}
