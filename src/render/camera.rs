//! Views and the orthographic camera: a view direction from azimuth and
//! elevation (or a named view), and the map from model coordinates to image
//! pixels that fits the model into the picture.

use super::RenderError;

/// A view direction in degrees. Azimuth 0, elevation 0 looks along +y (the
/// front view, z up); elevation 90 looks down −z (the top view, y up);
/// positive azimuth turns the eye towards +x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub azimuth: f64,
    pub elevation: f64,
}

impl View {
    pub const FRONT: View = View {
        azimuth: 0.0,
        elevation: 0.0,
    };
    pub const TOP: View = View {
        azimuth: 0.0,
        elevation: 90.0,
    };
    /// The isometric view: the eye on the diagonal (+1, −1, +1) direction
    /// seen from the front right above.
    pub const ISO: View = View {
        azimuth: 45.0,
        elevation: 35.264_389_682_754_654,
    };

    /// `front`, `top`, `iso`, or `AZIMUTH,ELEVATION` in degrees.
    pub fn parse(text: &str) -> Result<View, RenderError> {
        let t = text.trim().to_ascii_lowercase();
        match t.as_str() {
            "front" => return Ok(View::FRONT),
            "top" => return Ok(View::TOP),
            "iso" => return Ok(View::ISO),
            _ => {}
        }
        let bad = || RenderError::View(text.to_string());
        let (a, e) = t.split_once(',').ok_or_else(bad)?;
        let azimuth: f64 = a.trim().parse().map_err(|_| bad())?;
        let elevation: f64 = e.trim().parse().map_err(|_| bad())?;
        if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
            return Err(bad());
        }
        Ok(View { azimuth, elevation })
    }
}

/// An orthographic camera: image x grows to the right, image y downwards,
/// depth grows away from the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub right: [f64; 3],
    pub up: [f64; 3],
    /// From the model towards the eye.
    pub toward_eye: [f64; 3],
    /// Pixels per model unit.
    pub scale: f64,
    /// The model point that maps to the image centre.
    pub center: [f64; 3],
    pub width: u32,
    pub height: u32,
}

/// Fraction of the smaller image side left free around the model.
pub const MARGIN: f64 = 0.1;

impl Camera {
    /// Fits `points` into a `width`×`height` picture seen from `view`, leaving
    /// [`MARGIN`] free on each side of the tighter axis.
    pub fn fit(view: View, points: &[[f64; 3]], width: u32, height: u32) -> Camera {
        let (az, el) = (view.azimuth.to_radians(), view.elevation.to_radians());
        let toward_eye = [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()];
        let right = [az.cos(), az.sin(), 0.0];
        let up = cross(toward_eye, right);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in points {
            let (u, v) = (dot(*p, right), dot(*p, up));
            lo = [below(u, lo[0]), below(v, lo[1])];
            hi = [above(u, hi[0]), above(v, hi[1])];
        }
        if points.is_empty() {
            lo = [-1.0, -1.0];
            hi = [1.0, 1.0];
        }
        let extent = [(hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300)];
        let free = 1.0 - 2.0 * MARGIN;
        let scale = (width as f64 * free / extent[0]).min(height as f64 * free / extent[1]);
        let (cu, cv) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
        let center = [
            cu * right[0] + cv * up[0],
            cu * right[1] + cv * up[1],
            cu * right[2] + cv * up[2],
        ];
        Camera {
            right,
            up,
            toward_eye,
            scale,
            center,
            width,
            height,
        }
    }

    /// Image x and y in pixels (continuous: pixel i covers [i, i+1)) and the
    /// depth in model units (larger is farther).
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ];
        [
            0.5 * self.width as f64 + self.scale * dot(d, self.right),
            0.5 * self.height as f64 - self.scale * dot(d, self.up),
            -dot(d, self.toward_eye),
        ]
    }

    /// The depth [`Camera::project`] gives, alone (the same arithmetic, so
    /// the same bits): the depth range of a million nodes costs one dot
    /// product each instead of three.
    #[inline]
    pub fn depth(&self, p: [f64; 3]) -> f64 {
        let d = [
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ];
        -dot(d, self.toward_eye)
    }
}

/// `v` when it is below `bound`, else `bound`: `f64::min` for a bound that is
/// never NaN (a NaN `v` keeps the bound), in one `minsd` instead of the
/// three or four instructions `f64::min`'s NaN rule costs; a million nodes
/// make it count.
#[inline]
pub fn below(v: f64, bound: f64) -> f64 {
    if v < bound { v } else { bound }
}

/// `v` when it is above `bound`, else `bound` (see [`below`]).
#[inline]
pub fn above(v: f64, bound: f64) -> f64 {
    if v > bound { v } else { bound }
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_views_and_projection() {
        let pts = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]];
        let front = Camera::fit(View::FRONT, &pts, 100, 100);
        // x to the right, z up, y away from the eye.
        let p = front.project([1.0, -1.0, 1.0]);
        assert!((p[0] - 90.0).abs() < 1e-9 && (p[1] - 10.0).abs() < 1e-9);
        assert!(front.project([0.0, 1.0, 0.0])[2] > front.project([0.0, -1.0, 0.0])[2]);
        let top = Camera::fit(View::TOP, &pts, 100, 100);
        let q = top.project([1.0, 1.0, 0.0]);
        assert!((q[0] - 90.0).abs() < 1e-9 && (q[1] - 10.0).abs() < 1e-9);
        assert_eq!(
            View::parse("30, 20").ok(),
            Some(View {
                azimuth: 30.0,
                elevation: 20.0
            })
        );
        assert!(View::parse("sideways").is_err());
        assert!(View::parse("0,91").is_err());
    }
}
