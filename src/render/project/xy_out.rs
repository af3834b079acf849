//! Where the projection puts the nodes' unsnapped positions: an array of
//! pairs (`xy_f`), or, when every node has a light slot of its own (smooth
//! shading of one face), 16-byte records of position and light. Shading a
//! pixel reads its triangle's three corners at random: with the records a
//! corner costs one cache line instead of two (one in the positions, one in
//! the light). The projection streams over the nodes already, so the light
//! rides along: no pass of its own.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;
use std::mem::MaybeUninit;

/// What shading reads of a node: its unsnapped position in sample space and
/// its light on the front and the back side. Aligned to its size, so a
/// record never straddles two cache lines.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(16))]
pub struct XyLight {
    pub xy: [f32; 2],
    pub light: [f32; 2],
}

/// A block's slots for the unsnapped positions of its nodes.
pub(super) trait XyOut: Sized {
    fn len(&self) -> usize;

    /// Writes node `i`'s position.
    fn one(&mut self, i: usize, xy: [f32; 2]);

    /// Writes the positions of nodes `i..i + 4`, x and y in lanes.
    ///
    /// # Safety
    /// `i + 4 <= self.len()`.
    #[cfg(target_arch = "x86_64")]
    unsafe fn four(&mut self, i: usize, x: __m128, y: __m128);

    /// The slots of the nodes from `i` on.
    fn from(self, i: usize) -> Self;
}

impl XyOut for &mut [MaybeUninit<[f32; 2]>] {
    fn len(&self) -> usize {
        <[_]>::len(self)
    }

    #[inline(always)]
    fn one(&mut self, i: usize, xy: [f32; 2]) {
        self[i].write(xy);
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn four(&mut self, i: usize, x: __m128, y: __m128) {
        // SAFETY: slots `i..i + 4` exist (the caller's promise): eight f32s
        // in a row.
        unsafe {
            let to = self.as_mut_ptr().add(i).cast::<f32>();
            _mm_storeu_ps(to, _mm_unpacklo_ps(x, y));
            _mm_storeu_ps(to.add(4), _mm_unpackhi_ps(x, y));
        }
    }

    fn from(self, i: usize) -> Self {
        &mut self[i..]
    }
}

/// Records of position and light: `light[i]` goes with node `i`'s position.
pub(super) struct WithLight<'a> {
    pub light: &'a [[f32; 2]],
    pub to: &'a mut [MaybeUninit<XyLight>],
}

impl XyOut for WithLight<'_> {
    fn len(&self) -> usize {
        assert_eq!(self.light.len(), self.to.len());
        self.to.len()
    }

    #[inline(always)]
    fn one(&mut self, i: usize, xy: [f32; 2]) {
        self.to[i].write(XyLight {
            xy,
            light: self.light[i],
        });
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn four(&mut self, i: usize, x: __m128, y: __m128) {
        // SAFETY: nodes `i..i + 4` have light and a record (the caller's
        // promise, `len` checks the two agree): eight f32s of light in a
        // row, and four records of four f32s each, aligned to 16 bytes.
        unsafe {
            let light = self.light.as_ptr().add(i).cast::<f32>();
            let (l01, l23) = (_mm_loadu_ps(light), _mm_loadu_ps(light.add(4)));
            let (xy01, xy23) = (_mm_unpacklo_ps(x, y), _mm_unpackhi_ps(x, y));
            let to = self.to.as_mut_ptr().add(i).cast::<f32>();
            // (x0, y0, front0, back0), then (x1, y1, front1, back1): the
            // low and high halves of the pairs.
            _mm_store_ps(to, _mm_movelh_ps(xy01, l01));
            _mm_store_ps(to.add(4), _mm_movehl_ps(l01, xy01));
            _mm_store_ps(to.add(8), _mm_movelh_ps(xy23, l23));
            _mm_store_ps(to.add(12), _mm_movehl_ps(l23, xy23));
        }
    }

    fn from(self, i: usize) -> Self {
        WithLight {
            light: &self.light[i..],
            to: &mut self.to[i..],
        }
    }
}
