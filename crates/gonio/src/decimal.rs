//! Numbers as text: the shortest decimal that reads back to the same value, in exponent form for
//! very large or small magnitudes, and angles in degrees written so that they read back to the
//! radians they came from (`54.999999999999986` never appears where the file said `55`).

/// `v` in the shortest form that parses back to the same `f64`: positional notation for
/// 1e-5 ≤ |v| < 1e16 (and 0), exponent form (`1.7976931348623157e308`, `5e-324`) otherwise, so
/// that no number is printed with hundreds of digits. Non-finite values print as `NaN`, `inf`,
/// `-inf`.
pub fn shortest(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The value with the fewest significant decimal digits near `approx` for which `accept` holds,
/// trying 1 to 17 significant digits; `approx` itself when none does.
///
/// `approx` is a value computed back from a stored one (degrees from radians, γ = 180° − θ);
/// `accept(x)` says whether reading `x` reproduces the stored value exactly.
pub fn shortest_preimage(approx: f64, accept: impl Fn(f64) -> bool) -> f64 {
    if !approx.is_finite() {
        return approx;
    }
    for digits in 0..17 {
        if let Ok(x) = format!("{approx:.digits$e}").parse::<f64>() {
            if accept(x) {
                return x;
            }
        }
    }
    approx
}

/// The angle `radians` in degrees, as the shortest decimal `d` with `d.to_radians() == radians`
/// (the conversion every reader of the crate uses), so that an angle read as `55` is written as
/// `55`, not `54.999999999999986`.
pub fn degrees(radians: f64) -> f64 {
    shortest_preimage(radians.to_degrees(), |d| d.to_radians() == radians)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degrees_round_trip_as_read() {
        for d in [
            0.0, 55.0, 60.0, 15.0, 22.5, 0.1, 89.9, 90.0, 179.5, 180.0, 359.0, 1e-7, 33.333,
        ] {
            let r: f64 = f64::to_radians(d);
            assert_eq!(degrees(r), d, "{d}");
            assert_eq!(degrees(r).to_radians(), r);
        }
        // Not every radian value comes from a short decimal: still an exact preimage.
        let r = 0.123_456_789_012_345_67_f64;
        assert_eq!(degrees(r).to_radians(), r);
    }

    #[test]
    fn shortest_uses_exponent_for_extremes() {
        assert_eq!(shortest(1e308), "1e308");
        assert_eq!(shortest(f64::MAX), "1.7976931348623157e308");
        assert_eq!(shortest(5e-324), "5e-324");
        assert_eq!(shortest(-2.5e-7), "-2.5e-7");
        assert_eq!(shortest(0.25), "0.25");
        assert_eq!(shortest(123456.0), "123456");
        assert_eq!(shortest(0.0), "0");
        for v in [1e308, 5e-324, 1.0 / 3.0, 1e15 + 0.5, 1e-5] {
            assert_eq!(shortest(v).parse::<f64>().unwrap(), v);
            assert!(shortest(v).len() <= 24, "{}", shortest(v));
        }
    }

    #[test]
    fn diagram_messages_name_extreme_numbers_briefly() {
        // 5e-324° and 0° are distinct degrees but the same radians: the message says so with the
        // numbers as given, not `#1 = 0° follows 0°`.
        let e = crate::Diagram::from_degrees(&[0.0, 5e-324, 90.0], &[0.0], &[vec![1.0, 1.0, 1.0]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("#1 = 5e-324° follows 0°"), "{e}");
        let e = crate::Diagram::from_degrees(&[0.0, 90.0], &[0.0], &[vec![1.0, -1e308]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("= -1e308 is not"), "{e}");
    }
}
