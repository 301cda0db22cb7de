//! Parse-time validation of a photometric table, shared by both readers: round-off negatives,
//! the vertical range rule, the symmetry an IES file's horizontal angles imply (and the type A/B
//! axis rules), and a closing plane that differs from the first. Each either refuses the file with
//! a [`ParseError`] at the offending token or reports what it tolerated as a [`Warning`].

use super::tokens::{Cursor, Mark, Token};
use super::{ParseError, PhotometricType, Symmetry, Warning};

/// Negative values no larger in magnitude than this fraction of the table's largest value are
/// round-off and clamped to 0 (with a warning); anything more negative is an error.
pub(crate) const NEGATIVE_TOLERANCE: f64 = 1e-6;

/// Clamps round-off negatives to 0 (one warning), refuses real negatives (error at the token).
pub(crate) fn clamp_negative(
    cur: &Cursor,
    raw: &mut [f64],
    start: Mark,
    warnings: &mut Vec<Warning>,
) -> Result<(), ParseError> {
    // The token of value k, found again by scanning from `start` (only for a message).
    let at = |k: usize, msg: String| match cur.token_after(start, k) {
        Some(t) => cur.err_at(&t, msg),
        None => ParseError::new(0, 0, msg),
    };
    let max = raw.iter().fold(0.0f64, |a, &b| a.max(b));
    let tol = NEGATIVE_TOLERANCE * max;
    let mut first = None;
    let mut count = 0usize;
    for (k, v) in raw.iter_mut().enumerate() {
        if *v < 0.0 {
            if -*v <= tol {
                first.get_or_insert(k);
                count += 1;
                *v = 0.0;
            } else {
                return Err(at(
                    k,
                    format!("negative intensity {v} (intensities must be ≥ 0)"),
                ));
            }
        } else if *v == 0.0 {
            *v = 0.0; // turns −0 into +0
        }
    }
    if let Some(k) = first {
        let e = at(k, String::new());
        warnings.push(Warning {
            line: e.line,
            column: e.column,
            message: format!(
                "{count} tiny negative intensities (round-off, at most {NEGATIVE_TOLERANCE} × the maximum) clamped to 0"
            ),
        });
    }
    Ok(())
}

/// The measured γ range [first, last] with its ends snapped to 0°, 90° or 180° when within
/// [`crate::diagram::ANGLE_TOLERANCE_DEG`], and the standard range it falls short of, if any: (0–90, 90–180 or 0–180; the one a
/// range stopping short belongs to is 0–90 if it ends at or before 90°, 90–180 if it starts at or
/// after 90°, else 0–180). Nothing is added to the data: outside the measured range the map has no
/// light (docs/PHOTOMETRY.md, "Vertical range rule").
pub(crate) fn vertical_plan(vert: &[f64]) -> ((f64, f64), Option<(f64, f64)>) {
    let snap = |g: f64| crate::diagram::snap_deg(g, &[0.0, 90.0, 180.0]);
    let (a, b) = (snap(vert[0]), snap(vert[vert.len() - 1]));
    let standard = if b <= 90.0 {
        (0.0, 90.0)
    } else if a >= 90.0 {
        (90.0, 180.0)
    } else {
        (0.0, 180.0)
    };
    ((a, b), ((a, b) != standard).then_some(standard))
}

/// Checks the type C vertical angles and reports the padding rule as a warning.
pub(crate) fn check_vertical_c(
    cur: &Cursor,
    vert: &[f64],
    first: Option<&Token>,
    warnings: &mut Vec<Warning>,
) -> Result<(), ParseError> {
    if vert.len() < 2 {
        let msg = "at least two vertical angles are needed for type C photometry";
        return Err(match first {
            Some(t) => cur.err_at(t, msg),
            None => ParseError::new(0, 0, msg),
        });
    }
    let ((a, b), short) = vertical_plan(vert);
    if let Some((lo, hi)) = short {
        let (line, column) = first.map_or((0, 0), |t| (t.line, t.column));
        warnings.push(Warning {
            line,
            column,
            message: format!(
                "vertical angles {a}°–{b}° do not span {lo}–{hi}° (LM-63: 0–90°, 90–180° or 0–180°); \
                 no light is assumed outside the measured range: the map completes it with zero intensity"
            ),
        });
    }
    Ok(())
}

/// Classifies the stored planes of an IES file (any photometric type) and checks the vertical
/// angles. Errors point at the angle tokens.
#[allow(clippy::too_many_arguments)]
pub(crate) fn classify(
    ptype: PhotometricType,
    vert: &[f64],
    horiz: &[f64],
    raw: &[f64],
    vt: (Option<&Token>, Option<&Token>),
    ht: (Option<&Token>, Option<&Token>),
    cur: &Cursor,
    warnings: &mut Vec<Warning>,
) -> Result<Symmetry, ParseError> {
    let at = |t: Option<&Token>, msg: String| match t {
        Some(t) => cur.err_at(t, msg),
        None => ParseError::new(0, 0, msg),
    };
    if ptype != PhotometricType::C {
        if vert.len() < 2 || horiz.len() < 2 {
            return Err(at(
                vt.0,
                format!(
                    "type {ptype} photometry needs at least two vertical and two horizontal angles"
                ),
            ));
        }
        let horizontal = ab_axis_rule(ptype, "horizontal", horiz, ht.0, warnings);
        let vertical = ab_axis_rule(ptype, "vertical", vert, vt.0, warnings);
        return Ok(Symmetry::TypeAB {
            horizontal,
            vertical,
        });
    }
    check_vertical_c(cur, vert, vt.0, warnings)?;
    let n = horiz.len();
    let (a, b) = (horiz[0], horiz[n - 1]);
    let sym = if n == 1 {
        Symmetry::Rotational
    } else if a == 0.0 && b == 90.0 {
        Symmetry::Quadrant
    } else if a == 0.0 && b == 180.0 {
        Symmetry::BilateralC0C180
    } else if a == 90.0 && b == 270.0 {
        Symmetry::BilateralC90C270
    } else if b - a > 180.0 {
        if a != 0.0 {
            warnings.push(Warning {
                line: ht.0.map_or(0, |t| t.line),
                column: ht.0.map_or(0, |t| t.column),
                message: format!("the first horizontal angle is {a}°, not 0°"),
            });
        }
        if is_closing(horiz) {
            check_duplicate_plane(raw, vert.len(), n, ht.1, warnings);
        }
        Symmetry::None
    } else {
        return Err(at(
            ht.1,
            format!(
                "horizontal angles {a}°–{b}° match no supported symmetry \
                 (one angle, 0–90°, 0–180°, 90–270°, or a full set spanning more than 180°)"
            ),
        ));
    };
    Ok(sym)
}

/// LM-63's rule for each axis of a type A or B table: the angles run from −90° (full) or 0°
/// (symmetric about 0°, completed by mirroring) to 90°. Returns whether the axis is mirrored, and
/// warns, naming the rule and what was done, when the angles break it:
/// * first angle in (0°, 90°) (e.g. 1°): read as symmetric about 0° and mirrored, the band around 0°
///   interpolated between the first angle and its mirror image (never half the light dropped);
/// * first angle in (−90°, 0°) or last angle short of 90°: no light outside the measured range.
///
/// Ends within [`crate::diagram::ANGLE_TOLERANCE_DEG`] of −90°, 0° or 90° are those angles.
fn ab_axis_rule(
    ptype: PhotometricType,
    axis: &str,
    angles: &[f64],
    first: Option<&Token>,
    warnings: &mut Vec<Warning>,
) -> bool {
    let snap = |g: f64| crate::diagram::snap_deg(g, &[-90.0, 0.0, 90.0]);
    let (a, b) = (snap(angles[0]), snap(angles[angles.len() - 1]));
    let (line, column) = first.map_or((0, 0), |t| (t.line, t.column));
    let rule = format!(
        "type {ptype} {axis} angles must run from −90° (full) or 0° (symmetric about 0°) to 90° (LM-63)"
    );
    let mut warn = |what: String| {
        warnings.push(Warning {
            line,
            column,
            message: format!("{rule}; {what}"),
        })
    };
    let mirror = a >= 0.0;
    if a > 0.0 {
        warn(format!(
            "they start at {a}°: read as symmetric about 0° and mirrored, the light between −{a}° and {a}° \
             interpolated between the two mirrored planes"
        ));
    } else if a > -90.0 && a < 0.0 {
        warn(format!(
            "they start at {a}°: no light is assumed below {a}°"
        ));
    }
    if b < 90.0 {
        warn(format!("they end at {b}°: no light is assumed beyond {b}°"));
    }
    mirror
}

/// Warns when the closing plane (first + 360°) differs from the first plane; the first is kept.
pub(crate) fn check_duplicate_plane(
    raw: &[f64],
    n_v: usize,
    n_h: usize,
    last: Option<&Token>,
    warnings: &mut Vec<Warning>,
) {
    let first = &raw[..n_v];
    let closing = &raw[(n_h - 1) * n_v..n_h * n_v];
    if first != closing {
        warnings.push(Warning {
            line: last.map_or(0, |t| t.line),
            column: last.map_or(0, |t| t.column),
            message: "the closing plane (first angle + 360°) differs from the first plane; \
                      the first plane is kept"
                .into(),
        });
    }
}

/// Whether the last plane closes the set: it lies at the first angle + 360° (within 1e-9°).
pub(crate) fn is_closing(horiz: &[f64]) -> bool {
    let n = horiz.len();
    n > 1 && (horiz[n - 1] - horiz[0] - 360.0).abs() < 1e-9
}
