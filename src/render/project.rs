//! Nodes to sample space for the raster: each node's snapped x and y with its
//! depth normalised over the model's depth range, and its unsnapped x and y
//! for shading. Half a million nodes make the per-node instructions count,
//! so x and y are computed as the two lanes of one SSE2 vector: the same IEEE
//! operations in the same order as [`Camera::project`] followed by the
//! scalar scaling, clamping and snapping of [`scalar_node`], lane by lane
//! (nothing fused), so the same bits.

use super::camera::{Camera, DepthHint, above, below};
use super::raster::{Projected, Snapped};
use rayon::prelude::*;
use std::mem::MaybeUninit;

mod xy_out;
pub use xy_out::XyLight;
use xy_out::{WithLight, XyOut};

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2;

/// Nodes per unit of parallel work.
const BLOCK: usize = 1 << 13;
/// Far outside the picture only the clamped bounding box matters.
const LIMIT: f64 = 1e6;

/// Node positions in sample space (`ss` samples per pixel along each axis),
/// depths normalised to [0, 1].
/// `hint`, what the camera's fit learnt of these points' depths, spares the
/// depth range most of its pass. `light`, one per node (the nodes' own
/// light slots), goes with the unsnapped positions into
/// [`Projected::xy_light`] (then `xy_f` is left empty): shading reads a
/// corner's position and light from one record.
pub fn project(
    points: &[[f64; 3]],
    camera: &Camera,
    ss: usize,
    hint: Option<&DepthHint>,
    light: Option<&[[f32; 2]]>,
) -> Projected {
    let hinted = hint.and_then(|hint| hinted_depth_range(points, camera, hint));
    let (lo, hi) = hinted.unwrap_or_else(|| depth_range(points, camera));
    let range = if hi > lo { hi - lo } else { 1.0 };
    let map = NodeMap::new(camera, ss as f64, lo, range);
    let n = points.len();
    let mut snapped: Vec<Snapped> = Vec::with_capacity(n);
    if let Some(light) = light.filter(|light| light.len() == n) {
        let mut xy_light: Vec<XyLight> = Vec::with_capacity(n);
        (points.par_chunks(BLOCK))
            .zip(snapped.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
            .zip(light.par_chunks(BLOCK))
            .zip(xy_light.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
            .for_each(|(((from, to_snapped), light), to)| {
                map.block(from, to_snapped, WithLight { light, to })
            });
        // SAFETY: as below, with `light` (`n` long) cut alike.
        unsafe {
            snapped.set_len(n);
            xy_light.set_len(n);
        }
        return Projected {
            snapped,
            xy_f: Vec::new(),
            xy_light,
        };
    }
    let mut xy_f: Vec<[f32; 2]> = Vec::with_capacity(n);
    (points.par_chunks(BLOCK))
        .zip(snapped.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
        .zip(xy_f.spare_capacity_mut()[..n].par_chunks_mut(BLOCK))
        .for_each(|((from, to_snapped), to_xy)| map.block(from, to_snapped, to_xy));
    // SAFETY: the chunks above cover the first `n` slots of both vectors
    // (`points`, `..n` of each spare capacity, one block size), and
    // `NodeMap::block` writes every slot of its chunks.
    unsafe {
        snapped.set_len(n);
        xy_f.set_len(n);
    }
    Projected {
        snapped,
        xy_f,
        xy_light: Vec::new(),
    }
}

/// The least and greatest depth of the nodes ([`Camera::depth`]). Blocks
/// are folded in order and joined in block order with the same comparisons,
/// so the result is the serial fold's for any thread count.
fn depth_range(points: &[[f64; 3]], camera: &Camera) -> (f64, f64) {
    let blocks: Vec<(f64, f64)> = points
        .par_chunks(BLOCK)
        .map(|block| block_depth_range(block, camera))
        .collect();
    blocks
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (bl, bh)| {
            (below(bl, l), above(bh, h))
        })
}

/// [`depth_range`] of one block, serially.
fn block_depth_range(block: &[[f64; 3]], camera: &Camera) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            if let Some(bounds) = unsafe { avx2::depth_bounds(block, camera) } {
                return bounds;
            }
        }
    }
    // A copy: its fields stay in registers over the loop.
    let camera = *camera;
    block
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
            let z = camera.depth(*q);
            (below(z, l), above(z, h))
        })
}

/// Relative bound on the rounding that parts a node's computed depth from
/// `centre·toward_eye` minus its computed `p·toward_eye`: about 2^−50 of the
/// sum of `(|p_k| + |centre_k|)·|toward_eye_k|` (two dot products of three
/// terms and a difference); 2^−40 leaves room for the rounding of the
/// bound itself.
const ROUNDING: f64 = 1.0 / (1u64 << 40) as f64;
/// Coordinates below this keep every product and sum of a depth finite.
const MOST_MAGNITUDE: f64 = 1e100;

/// [`depth_range`] from what the camera's fit learnt ([`DepthHint`]): a
/// node's depth is `centre·toward_eye − p·toward_eye` up to a rounding the
/// magnitudes bound (`slack`), so the farthest node lies in a block whose
/// least `p·toward_eye` is within twice that of the least of all, and the
/// nearest likewise; only those blocks are folded, in block order, so the
/// bounds are the serial fold's values. `None` (fold them all) when the hint
/// is not for these points and this view, a magnitude is too large (or
/// infinite, or no node is a number), or a bound is a zero: the serial fold
/// keeps the sign of the first zero it meets, which a skipped block may hold.
fn hinted_depth_range(
    points: &[[f64; 3]],
    camera: &Camera,
    hint: &DepthHint,
) -> Option<(f64, f64)> {
    let blocks: Vec<_> = hint.blocks(points, camera.toward_eye)?.collect();
    let empty = (f64::INFINITY, f64::NEG_INFINITY, [0.0f64; 3]);
    let (least, most, magnitude) = (blocks.iter()).fold(empty, |(l, h, m), (_, d)| {
        let m = std::array::from_fn(|k| above(d.magnitude[k], m[k]));
        (below(d.toward.0, l), above(d.toward.1, h), m)
    });
    let c = camera.center;
    let small = (0..3).all(|k| magnitude[k] < MOST_MAGNITUDE && c[k].abs() < MOST_MAGNITUDE);
    if !(small && least.is_finite() && most.is_finite()) {
        return None;
    }
    let t = camera.toward_eye;
    let spread: f64 = (0..3)
        .map(|k| (magnitude[k] + c[k].abs()) * t[k].abs())
        .sum();
    // Twice a node's rounding, and underflow's absolute part.
    let slack = 2.0 * (spread * ROUNDING + f64::MIN_POSITIVE);
    let (near, far) = (most - slack, least + slack);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (block, d) in blocks {
        let (holds_nearest, holds_farthest) = (d.toward.1 >= near, d.toward.0 <= far);
        if holds_nearest || holds_farthest {
            let (bl, bh) = block_depth_range(block, camera);
            if holds_nearest {
                lo = below(bl, lo);
            }
            if holds_farthest {
                hi = above(bh, hi);
            }
        }
    }
    (lo != 0.0 && hi != 0.0).then_some((lo, hi))
}

/// What one node's projection needs, as plain values (copied into each
/// block's loop, so they stay in registers instead of being reloaded
/// through a reference per node).
#[derive(Clone, Copy)]
struct NodeMap {
    center: [f64; 3],
    toward_eye: [f64; 3],
    /// `[right[k], up[k]]`: the x and y lanes' factors of coordinate k.
    right_up: [[f64; 2]; 3],
    /// `[w/2, h/2]` and `[scale, −scale]`.
    half: [f64; 2],
    scale: [f64; 2],
    ss: f64,
    lo: f64,
    range: f64,
    #[cfg(not(target_arch = "x86_64"))]
    camera: Camera,
}

impl NodeMap {
    fn new(camera: &Camera, ss: f64, lo: f64, range: f64) -> NodeMap {
        NodeMap {
            center: camera.center,
            toward_eye: camera.toward_eye,
            right_up: std::array::from_fn(|k| [camera.right[k], camera.up[k]]),
            half: [0.5 * camera.width as f64, 0.5 * camera.height as f64],
            scale: [camera.scale, -camera.scale],
            ss,
            lo,
            range,
            #[cfg(not(target_arch = "x86_64"))]
            camera: *camera,
        }
    }

    /// Projects a block of nodes into the slots of `snapped` and `xy_f`
    /// (one per node: every slot is written).
    fn block(self, points: &[[f64; 3]], snapped: &mut [MaybeUninit<Snapped>], xy_f: impl XyOut) {
        assert!(snapped.len() == points.len() && xy_f.len() == points.len());
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2 (checked just above).
                unsafe { self.block_avx2(points, snapped, xy_f) };
                return;
            }
            // SAFETY: SSE2 is part of every x86-64.
            unsafe { self.block_sse2(points, snapped, xy_f) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let mut xy_f = xy_f;
        #[cfg(not(target_arch = "x86_64"))]
        for (i, (q, s)) in points.iter().zip(snapped).enumerate() {
            let (node, xy) = scalar_node(&self.camera, self.ss, self.lo, self.range, *q);
            s.write(node);
            xy_f.one(i, xy);
        }
    }

    /// The node-by-node lanes: [`NodeMap::block_avx2`]'s remainder, and
    /// the path of processors without AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    fn block_sse2(
        self,
        points: &[[f64; 3]],
        snapped: &mut [MaybeUninit<Snapped>],
        mut xy_f: impl XyOut,
    ) {
        use std::arch::x86_64::*;
        let pair = |v: [f64; 2]| _mm_set_pd(v[1], v[0]);
        let [f0, f1, f2] = self.right_up.map(pair);
        let (half, scale) = (pair(self.half), pair(self.scale));
        let ss = _mm_set1_pd(self.ss);
        let (limit_lo, limit_hi) = (_mm_set1_pd(-LIMIT), _mm_set1_pd(LIMIT));
        let (sixteen, sign, one_half) = (_mm_set1_pd(16.0), _mm_set1_pd(-0.0), _mm_set1_pd(0.5));
        let (c, t) = (self.center, self.toward_eye);
        for (i, (q, s)) in points.iter().zip(snapped).enumerate() {
            let d = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
            // `Camera::depth`: −(d·toward_eye), summed as `dot` sums.
            let z = -(d[0] * t[0] + d[1] * t[1] + d[2] * t[2]);
            let z = ((z - self.lo) / self.range) as f32;
            // Lanes (x, y): x = w/2 + s·(d·right), y = h/2 + (−s)·(d·up),
            // which is h/2 − s·(d·up) bit for bit (negation is exact).
            let dots = _mm_add_pd(
                _mm_add_pd(
                    _mm_mul_pd(_mm_set1_pd(d[0]), f0),
                    _mm_mul_pd(_mm_set1_pd(d[1]), f1),
                ),
                _mm_mul_pd(_mm_set1_pd(d[2]), f2),
            );
            let image = _mm_add_pd(half, _mm_mul_pd(scale, dots));
            // `clamp`: `maxpd`/`minpd` return their second operand when
            // either is NaN, so a NaN stays NaN as `f64::clamp` keeps it.
            let v = _mm_min_pd(limit_hi, _mm_max_pd(limit_lo, _mm_mul_pd(image, ss)));
            let xy = _mm_cvtpd_ps(v);
            // `snap`: v·16 plus a half with v's sign, truncated; a NaN lane
            // is zeroed first, as `as i32` turns NaN into 0.
            let v16 = _mm_mul_pd(v, sixteen);
            let rounded = _mm_add_pd(v16, _mm_or_pd(_mm_and_pd(v16, sign), one_half));
            let rounded = _mm_and_pd(rounded, _mm_cmpord_pd(rounded, rounded));
            let s_bits = _mm_cvtsi128_si64(_mm_cvttpd_epi32(rounded)) as u64;
            let xy_bits = _mm_cvtsi128_si64(_mm_castps_si128(xy)) as u64;
            s.write(Snapped {
                x: s_bits as u32 as i32,
                y: (s_bits >> 32) as u32 as i32,
                z,
            });
            xy_f.one(
                i,
                [
                    f32::from_bits(xy_bits as u32),
                    f32::from_bits((xy_bits >> 32) as u32),
                ],
            );
        }
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
    use std::mem::MaybeUninit;

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
            let proj = project(&points, &camera, ss, None, None);
            assert_eq!(proj.snapped.len(), points.len());
            assert!(proj.xy_light.is_empty());
            // With the nodes' light: records of the same positions and
            // that light, the same snapped nodes, no pairs.
            let light = node_light(points.len());
            let lit = project(&points, &camera, ss, None, Some(&light));
            assert!(lit.xy_f.is_empty());
            assert_eq!(lit.xy_light.len(), points.len());
            for (i, r) in lit.xy_light.iter().enumerate() {
                assert_eq!(r.xy.map(f32::to_bits), proj.xy_f[i].map(f32::to_bits));
                assert_eq!(r.light.map(f32::to_bits), light[i].map(f32::to_bits));
                let (a, b) = (lit.snapped[i], proj.snapped[i]);
                assert_eq!((a.x, a.y, a.z.to_bits()), (b.x, b.y, b.z.to_bits()));
            }
            // Light of another length is not the nodes': pairs.
            let other = project(&points, &camera, ss, None, Some(&light[1..]));
            assert!(other.xy_light.is_empty());
            assert_eq!(other.xy_f.len(), points.len());
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

    /// Distinct light per node (NaN and −0 among them: copied, not computed).
    fn node_light(n: usize) -> Vec<[f32; 2]> {
        (0..n)
            .map(|i| match i % 97 {
                5 => [f32::NAN, -0.0],
                k => [k as f32 / 96.0, 1.0 - i as f32 / n as f32],
            })
            .collect()
    }

    /// Projects `points` with `light` through a block path into records.
    fn records_by_block(
        points: &[[f64; 3]],
        light: &[[f32; 2]],
        path: impl FnOnce(&[[f64; 3]], &mut [MaybeUninit<Snapped>], WithLight),
    ) -> Vec<XyLight> {
        let mut snapped = vec![MaybeUninit::new(Snapped::default()); points.len()];
        let mut to = vec![MaybeUninit::new(XyLight::default()); points.len()];
        path(points, &mut snapped, WithLight { light, to: &mut to });
        // SAFETY: every slot was initialised above (and written again).
        to.into_iter().map(|r| unsafe { r.assume_init() }).collect()
    }

    /// One of `NodeMap`'s block paths.
    type BlockPath =
        fn(NodeMap, &[[f64; 3]], &mut [MaybeUninit<Snapped>], &mut [MaybeUninit<[f32; 2]>]);

    /// Projects `points` through `path`.
    fn by_block(
        map: NodeMap,
        points: &[[f64; 3]],
        path: BlockPath,
    ) -> (Vec<Snapped>, Vec<[f32; 2]>) {
        let mut snapped = vec![MaybeUninit::new(Snapped::default()); points.len()];
        let mut xy_f = vec![MaybeUninit::new([0.0f32; 2]); points.len()];
        path(map, points, &mut snapped, &mut xy_f);
        // SAFETY: every slot was initialised above (and written again).
        let read = |v: Vec<MaybeUninit<Snapped>>| v.into_iter().map(|s| unsafe { s.assume_init() });
        let xy = xy_f.into_iter().map(|f| unsafe { f.assume_init() });
        (read(snapped).collect(), xy.collect())
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn four_node_lanes_project_as_the_scalar_code_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let points = awkward_points();
        for (view, ss) in [(View::ISO, 2), (View::TOP, 3), (View::FRONT, 1)] {
            let camera = Camera::fit(view, &points[..4000], 640, 480);
            let (lo, hi) = depth_range(&points, &camera);
            let map = NodeMap::new(&camera, ss as f64, lo, hi - lo);
            // Each shift puts the far, NaN and −0 points in other lanes
            // and leaves another remainder for the node-by-node lanes.
            for shift in 0..4 {
                let part = &points[shift..];
                let avx2 = |m: NodeMap, p: &[[f64; 3]], s: &mut [_], f: &mut [_]| unsafe {
                    m.block_avx2(p, s, f)
                };
                let sse2 = |m: NodeMap, p: &[[f64; 3]], s: &mut [_], f: &mut [_]| unsafe {
                    m.block_sse2(p, s, f)
                };
                let (four, four_xy) = by_block(map, part, avx2);
                let (two, two_xy) = by_block(map, part, sse2);
                // The records' paths: the same positions, each node's light.
                let light = node_light(part.len());
                let four_records =
                    records_by_block(part, &light, |p, s, f| unsafe { map.block_avx2(p, s, f) });
                let two_records =
                    records_by_block(part, &light, |p, s, f| unsafe { map.block_sse2(p, s, f) });
                for (i, xy) in four_xy.iter().enumerate() {
                    for r in [four_records[i], two_records[i]] {
                        assert_eq!(r.xy.map(f32::to_bits), xy.map(f32::to_bits), "node {i}");
                        assert_eq!(r.light.map(f32::to_bits), light[i].map(f32::to_bits));
                    }
                }
                for (i, q) in part.iter().enumerate() {
                    let (want, want_xy) = scalar_node(&camera, ss as f64, lo, hi - lo, *q);
                    for (got, got_xy) in [(four[i], four_xy[i]), (two[i], two_xy[i])] {
                        assert_eq!((got.x, got.y), (want.x, want.y), "node {i}");
                        assert_eq!(got.z.to_bits(), want.z.to_bits(), "node {i}");
                        assert_eq!(got_xy.map(f32::to_bits), want_xy.map(f32::to_bits));
                    }
                }
                // The NaN coordinates reach the lanes: x, y snap to 0.
                let nan = 4003 - shift;
                assert_eq!((four[nan].x, four[nan].y), (0, 0));
                assert!(four[nan].z.is_nan());
            }
        }
    }

    #[test]
    fn depth_range_is_the_serial_fold() {
        let points = awkward_points();
        let fitted = Camera::fit(View::ISO, &points[..4000], 800, 600);
        // Seen along z through the origin, a flat square has depths of
        // either zero, in an order the lanes do not keep: the first zero
        // the serial fold meets gives each bound's sign.
        let flat: Vec<[f64; 3]> = (0..4003)
            .map(|i| {
                let t = i as f64 * 0.37;
                [t.sin(), t.cos(), if i % 3 == 1 { -0.0 } else { 0.0 }]
            })
            .collect();
        let along_z = Camera {
            center: [0.0, 0.0, 0.0],
            toward_eye: [0.0, 0.0, 1.0],
            ..fitted
        };
        let mut zeros = 0;
        for (camera, points) in [(&fitted, &points[..]), (&along_z, &flat[..])] {
            for shift in 0..5 {
                let part = &points[shift..];
                let serial = part
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                        let z = camera.depth(*q);
                        (below(z, l), above(z, h))
                    });
                let got = depth_range(part, camera);
                assert_eq!(
                    (got.0.to_bits(), got.1.to_bits()),
                    (serial.0.to_bits(), serial.1.to_bits())
                );
                zeros += usize::from(serial.0 == 0.0);
            }
        }
        assert_eq!(zeros, 5);
        // The lanes alone: the bounds of the awkward points (NaN, infinite
        // and far ones in every lane), and no answer for the zeros.
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            for shift in 0..4 {
                let part = &points[shift..];
                let want = depth_range(part, &fitted);
                // SAFETY: the CPU has AVX2 (checked just above).
                let got = unsafe { avx2::depth_bounds(part, &fitted) };
                assert_eq!(
                    got.map(|(l, h)| (l.to_bits(), h.to_bits())),
                    Some((want.0.to_bits(), want.1.to_bits()))
                );
                assert_eq!(
                    unsafe { avx2::depth_bounds(&flat[shift..], &along_z) },
                    None
                );
            }
        }
    }

    #[test]
    fn hinted_depth_range_is_the_serial_fold() {
        let points = awkward_points();
        // Three blocks and a part of one (the far points in each), and
        // nodes of equal depth in several blocks (a copy shifted across).
        let many: Vec<[f64; 3]> = (0..5)
            .flat_map(|_| points[..4002].iter().copied())
            .collect();
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        let key = |p: &Projected| {
            let snapped = p.snapped.iter().map(|s| (s.x, s.y, s.z.to_bits()));
            let xy = p.xy_f.iter().map(|v| v.map(f32::to_bits));
            (snapped.collect::<Vec<_>>(), xy.collect::<Vec<_>>())
        };
        for view in [
            View::ISO,
            View::TOP,
            View::FRONT,
            View {
                azimuth: 200.0,
                elevation: -30.0,
            },
        ] {
            let (camera, hint) = Camera::fit_with_depths(view, &many, 640, 480);
            assert_eq!(camera, Camera::fit(view, &many, 640, 480));
            let want = depth_range(&many, &camera);
            let got = hinted_depth_range(&many, &camera, &hint);
            let bits = |(l, h): (f64, f64)| (l.to_bits(), h.to_bits());
            assert_eq!(got.map(bits), avx2.then_some(bits(want)), "{view:?}");
            // Other points, or another view: no hint.
            assert_eq!(hinted_depth_range(&many[1..], &camera, &hint), None);
            assert_eq!(hinted_depth_range(&many.clone(), &camera, &hint), None);
            let turned = Camera {
                toward_eye: camera.up,
                ..camera
            };
            assert_eq!(hinted_depth_range(&many, &turned, &hint), None);
            let with = project(&many, &camera, 2, Some(&hint), None);
            assert_eq!(key(&with), key(&project(&many, &camera, 2, None, None)));
        }
        // NaN and infinite coordinates: no hint, the fold of every block.
        let (camera, hint) = Camera::fit_with_depths(View::ISO, &points, 640, 480);
        assert_eq!(hinted_depth_range(&points, &camera, &hint), None);
        let with = project(&points, &camera, 2, Some(&hint), None);
        assert_eq!(key(&with), key(&project(&points, &camera, 2, None, None)));
        // Seen from the front, depth is y: nodes at y = ±0 and behind make
        // the farthest depth a zero, whose sign the serial fold's first zero
        // gives: no hint.
        let edge_on: Vec<[f64; 3]> = (0..20_000)
            .map(|i| {
                let t = i as f64 * 0.37;
                let y = match i % 3 {
                    0 => 0.0,
                    1 => -0.0,
                    _ => -t.sin().abs() - 1.0,
                };
                [t.sin(), y, t.cos()]
            })
            .collect();
        let (camera, hint) = Camera::fit_with_depths(View::FRONT, &edge_on, 640, 480);
        let want = depth_range(&edge_on, &camera);
        assert_eq!(want.1, 0.0);
        assert_eq!(hinted_depth_range(&edge_on, &camera, &hint), None);
        let with = project(&edge_on, &camera, 2, Some(&hint), None);
        assert_eq!(key(&with), key(&project(&edge_on, &camera, 2, None, None)));
    }
}
