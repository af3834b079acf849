//! The grid cell of a coordinate, `x.floor() as i64`, without the call:
//! on x86-64 without SSE4.1 `f64::floor` is a function of the standard
//! library's libm (about 20 instructions and a call), and the welder's and
//! the overlap test's grids take it three times per point or box.

/// `x.floor() as i64` exactly, for every `x` (NaN gives 0, values beyond the
/// range of `i64` saturate, as the cast does).
pub(super) fn floor_index(x: f64) -> i64 {
    let truncated = x as i64;
    // Truncation rounds a negative fraction up; floor rounds it down.
    if (truncated as f64) > x {
        truncated.saturating_sub(1)
    } else {
        truncated
    }
}

#[cfg(test)]
mod tests {
    use super::floor_index;

    #[test]
    fn floor_index_is_the_cast_floor() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1.0 - f64::EPSILON,
            1.0 - f64::EPSILON / 2.0,
            -(1.0 - f64::EPSILON / 2.0),
            2.5,
            -2.5,
            4503599627370495.5,
            -4503599627370495.5,
            9.3e18,
            -9.3e18,
            i64::MAX as f64,
            i64::MIN as f64,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        // Cells of a shifted grid, as the overlap test's keys are.
        values.extend((-2000..2000).map(|k| k as f64 * 0.37 + 0.381_966_011_250_105_1));
        for x in values {
            assert_eq!(floor_index(x), x.floor() as i64, "{x}");
        }
        assert_eq!(floor_index(-0.25), -1);
        assert_eq!(floor_index(f64::NEG_INFINITY), i64::MIN);
    }
}
