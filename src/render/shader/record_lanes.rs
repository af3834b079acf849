//! [`lanes`](super::lanes) when each node's position and light are one
//! record ([`XyLight`]): a lane's triangle and its three records are read
//! with plain loads (a record is one 16-byte load) and turned into vectors
//! of x, y and light by shuffles, instead of twelve gathers of one float per
//! lane. The queue's columns, stored one by one, are read one by one too: a
//! vector load of them would wait for the stores to retire.

use super::Shader;
use super::lanes::{LANES, LaneInputs};
use crate::render::project::XyLight;
use std::arch::x86_64::*;

impl Shader<'_, '_> {
    /// What the lanes' colours need, read from the nodes' records; `None`
    /// when a lane shows a side without a known colour or an index is out
    /// of range.
    #[target_feature(enable = "avx2")]
    pub(super) fn record_inputs(
        &self,
        ids: &[u32; LANES],
        sx: &[u32; LANES],
    ) -> Option<LaneInputs> {
        // Bit i: lane i shows a back side.
        let backs = (0..LANES).fold(0u32, |m, i| m | (ids[i] & 1) << i);
        let unknown = |side: usize| self.sides[side].is_none();
        if (unknown(0) && backs != 0xff) || (unknown(1) && backs != 0) {
            return None;
        }
        // Per lane its triangle's three records, and whether the triangle
        // names one node thrice (its slots all one).
        let mut records = [[_mm_setzero_ps(); 3]; LANES];
        let mut one_node = 0u32;
        for (i, lane) in records.iter_mut().enumerate() {
            let t = *self.tris.get((ids[i] >> 1) as usize)?;
            for (k, &n) in t.iter().enumerate() {
                let r: *const XyLight = self.records.get(n as usize)?;
                // SAFETY: a record is four f32s aligned to 16 bytes.
                lane[k] = unsafe { _mm_load_ps(r.cast()) };
            }
            one_node |= u32::from(t[0] == t[1] && t[1] == t[2]) << i;
        }
        // Corner k of lanes 0–7 as x, y, front and back vectors: lanes i and
        // i + 4 share a vector, and each half is a 4×4 transposition.
        let mut corners = [[_mm256_setzero_ps(); 4]; 3];
        for (k, corner) in corners.iter_mut().enumerate() {
            let pair = |i: usize| _mm256_set_m128(records[i + 4][k], records[i][k]);
            let (a, b, c, d) = (pair(0), pair(1), pair(2), pair(3));
            // (x0 x1 y0 y1), (f0 f1 b0 b1), (x2 x3 y2 y3), (f2 f3 b2 b3) per half.
            let (ab_lo, ab_hi) = (_mm256_unpacklo_ps(a, b), _mm256_unpackhi_ps(a, b));
            let (cd_lo, cd_hi) = (_mm256_unpacklo_ps(c, d), _mm256_unpackhi_ps(c, d));
            let join = |lo: __m256, hi: __m256, high: bool| {
                let (lo, hi) = (_mm256_castps_pd(lo), _mm256_castps_pd(hi));
                _mm256_castpd_ps(if high {
                    _mm256_unpackhi_pd(lo, hi)
                } else {
                    _mm256_unpacklo_pd(lo, hi)
                })
            };
            *corner = [
                join(ab_lo, cd_lo, false),
                join(ab_lo, cd_lo, true),
                join(ab_hi, cd_hi, false),
                join(ab_hi, cd_hi, true),
            ];
        }
        // Lane i's bit of `bits` as all ones or zeros.
        let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let mask = |bits: u32| {
            _mm256_cmpeq_epi32(
                _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits),
                lane_bits,
            )
        };
        let is_back = _mm256_castsi256_ps(mask(backs));
        // Each corner's light on the lane's side (no `array::map`: a library
        // function without AVX2 would pass the vectors through memory).
        let side = |[_, _, front, back]: [__m256; 4]| _mm256_blendv_ps(front, back, is_back);
        let [a, b, c] = corners;
        let back = _mm256_and_si256(mask(backs), _mm256_set1_epi32(1));
        let columns = _mm256_setr_epi32(
            sx[0] as i32,
            sx[1] as i32,
            sx[2] as i32,
            sx[3] as i32,
            sx[4] as i32,
            sx[5] as i32,
            sx[6] as i32,
            sx[7] as i32,
        );
        Some(LaneInputs {
            corners: [a[0], a[1], b[0], b[1], c[0], c[1]],
            light: [side(a), side(b), side(c)],
            one_slot: mask(one_node),
            back,
            sx: columns,
        })
    }
}
