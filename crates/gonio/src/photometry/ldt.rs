//! EULUMDAT reader.

use super::tokens::{check_angles, excerpt, parse_number, strip_bom, text, Cursor, Lines};
use super::{
    expand, FileFormat, LampSet, LdtInfo, ParseError, PhotometricType, Photometry, Symmetry, Tilt,
    Version, Warning, MAX_ANGLES, MAX_LAMP_SETS,
};
use crate::diagram::MAX_NODES;

/// Line-by-line reader of the header fields (one line at a time: nothing is stored per line).
struct Fields<'a> {
    bytes: &'a [u8],
    lines: Lines<'a>,
    /// Lines taken so far (the 1-based number of the last one taken).
    next: usize,
}

impl<'a> Fields<'a> {
    fn eof(&self, what: &str) -> ParseError {
        // Just after the last byte of the last line (a scan, on this error path only).
        let mut n = 0;
        let mut last = None;
        for l in Lines::new(self.bytes) {
            n += 1;
            last = Some(l.len());
        }
        let (l, c) = match last {
            Some(len) => (n, len + 1),
            None => (1, 1),
        };
        ParseError::new(l, c, format!("unexpected end of file: expected {what}"))
    }

    /// The next line, consumed.
    fn take(&mut self, what: &str) -> Result<&'a [u8], ParseError> {
        let l = self.lines.next().ok_or_else(|| self.eof(what))?;
        self.next += 1;
        Ok(l)
    }

    /// The next line as text.
    fn text(&mut self, what: &str) -> Result<String, ParseError> {
        Ok(text(self.take(what)?))
    }

    /// The next line as a number (decimal comma allowed); (value, line, column).
    fn number(&mut self, what: &str) -> Result<(f64, usize, usize), ParseError> {
        let l = self.take(what)?;
        let lno = self.next;
        let lead = l.iter().take_while(|b| b.is_ascii_whitespace()).count();
        let body = l[lead..].trim_ascii_end();
        match parse_number(body, true) {
            Some(v) => Ok((v, lno, lead + 1)),
            None => Err(ParseError::new(
                lno,
                lead + 1,
                format!("expected a number ({what}), found `{}`", excerpt(body)),
            )),
        }
    }

    /// A number that is not needed for the distribution: an empty line reads as 0 (warning).
    fn lenient(&mut self, what: &str, warnings: &mut Vec<Warning>) -> Result<f64, ParseError> {
        if let Some(l) = self.lines.clone().next() {
            if l.trim_ascii().is_empty() {
                self.lines.next();
                self.next += 1;
                warnings.push(Warning {
                    line: self.next,
                    column: 1,
                    message: format!("{what} is empty; 0 assumed"),
                });
                return Ok(0.0);
            }
        }
        Ok(self.number(what)?.0)
    }

    /// An integer in [min, max].
    fn integer(
        &mut self,
        what: &str,
        min: i64,
        max: i64,
    ) -> Result<(i64, usize, usize), ParseError> {
        let (v, l, c) = self.number(what)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(ParseError::new(
                l,
                c,
                format!("{what} must be an integer from {min} to {max}, found {v}"),
            ));
        }
        Ok((v as i64, l, c))
    }
}

pub(crate) fn read_ldt(bytes: &[u8]) -> Result<Photometry, ParseError> {
    let bytes = strip_bom(bytes);
    if Lines::new(bytes).all(|l| l.trim_ascii().is_empty()) {
        return Err(ParseError::new(0, 0, "the file is empty"));
    }
    let mut w = Vec::new();
    let mut f = Fields {
        bytes,
        lines: Lines::new(bytes),
        next: 0,
    };
    let company = f.text("company identification (line 1)")?;
    let (ityp, il, ic) = f.integer("type indicator Ityp", i64::MIN / 2, i64::MAX / 2)?;
    let (isym, sl, sc) = f.integer("symmetry indicator Isym", 0, 4)?;
    let (mc, mcl, mcc) = f.integer("number of C planes Mc", 1, MAX_ANGLES as i64)?;
    let mc = mc as usize;
    let dc = f.lenient("distance between C planes Dc", &mut w)?;
    let (ng, ngl, ngc) = f.integer("number of γ angles Ng", 1, MAX_ANGLES as i64)?;
    let ng = ng as usize;
    let dg = f.lenient("distance between γ angles Dg", &mut w)?;
    let report_number = f.text("measurement report number")?;
    let luminaire_name = f.text("luminaire name")?;
    let luminaire_number = f.text("luminaire number")?;
    let file_name = f.text("file name")?;
    let date_user = f.text("date / user")?;
    let mut dims = [0.0; 3];
    for (d, what) in
        dims.iter_mut()
            .zip(["luminaire length", "luminaire width", "luminaire height"])
    {
        *d = f.lenient(what, &mut w)?;
    }
    let mut area = [0.0; 2];
    for (d, what) in area
        .iter_mut()
        .zip(["luminous area length", "luminous area width"])
    {
        *d = f.lenient(what, &mut w)?;
    }
    let mut heights = [0.0; 4];
    for (d, what) in heights.iter_mut().zip([
        "luminous area height C0",
        "luminous area height C90",
        "luminous area height C180",
        "luminous area height C270",
    ]) {
        *d = f.lenient(what, &mut w)?;
    }
    let dff = f.lenient("downward flux fraction DFF", &mut w)?;
    let lorl = f.lenient("light output ratio LORL", &mut w)?;
    let (cfli, cl, cc) = f.number("conversion factor for luminous intensities")?;
    let tilt_deg = f.lenient("tilt during measurement", &mut w)?;
    let (n_sets, nl, nc) = f.integer("number of lamp sets", 0, MAX_LAMP_SETS as i64)?;
    let n_sets = n_sets as usize;
    if f.lines.clone().take(6 * n_sets).count() < 6 * n_sets {
        return Err(ParseError::new(
            nl,
            nc,
            format!(
                "{n_sets} lamp sets declared (6 lines each), but only {} lines follow",
                f.lines.clone().count()
            ),
        ));
    }
    let mut lamp_sets = Vec::with_capacity(n_sets);
    for s in 1..=n_sets {
        let (count, _, _) = f.integer(
            &format!("number of lamps of set {s}"),
            i64::MIN / 2,
            i64::MAX / 2,
        )?;
        let description = f.text("lamp type")?;
        let (flux, _, _) = f.number(&format!("total luminous flux of lamp set {s}"))?;
        let color = f.text("colour appearance")?;
        let color_rendering = f.text("colour rendering group")?;
        let watts = f.lenient("wattage including ballast", &mut w)?;
        lamp_sets.push(LampSet {
            count,
            description,
            flux_lm: flux,
            color,
            color_rendering,
            watts,
        });
    }

    // The rest is read as white-space separated numbers (one per line in the standard layout).
    let first_data_line = f.next + 1;
    let mut cur = Cursor::new(f.lines.rest(), first_data_line, false, true);
    let (dr, _) = cur.numbers(10, "direct ratio")?;
    let mut direct_ratios = [0.0; 10];
    direct_ratios.copy_from_slice(&dr);

    // Stored planes for Isym: first stored plane index (0-based) and number of planes.
    let (start, planes) = match isym {
        0 => (0, mc),
        1 => (0, 1),
        2 => (0, mc / 2 + 1),
        3 => (3 * mc / 4, mc / 2 + 1),
        _ => (0, mc / 4 + 1),
    };
    let divisor = match isym {
        2 => 2,
        3 | 4 => 4,
        _ => 1,
    };
    if mc % divisor != 0 {
        return Err(ParseError::new(
            mcl,
            mcc,
            format!("Mc = {mc} C planes cannot be halved/quartered as Isym {isym} requires (Mc must be a multiple of {divisor})"),
        ));
    }
    let values = planes
        .checked_mul(ng)
        .filter(|&c| c <= MAX_NODES)
        .ok_or_else(|| {
            ParseError::new(
                ngl,
                ngc,
                format!("{planes} × {ng} values exceed the limit of {MAX_NODES}"),
            )
        })?;
    let needed = mc + ng + values;
    if !cur.has_at_least(needed) {
        return Err(ParseError::new(
            mcl,
            mcc,
            format!(
                "the file declares Mc = {mc}, Ng = {ng} with Isym {isym} ({needed} numbers after the direct ratios), \
                 but only {} values follow",
                cur.remaining()
            ),
        ));
    }
    let (c_angles, ct) = cur.numbers(mc, "C angle")?;
    check_angles(&cur, &c_angles, &ct, "C angle", 0.0, 360.0)?;
    let (gamma, gt) = cur.numbers(ng, "γ angle")?;
    check_angles(&cur, &gamma, &gt, "γ angle", 0.0, 180.0)?;
    let (mut raw, raw_at) = cur.values(values, "luminous intensity (cd/klm)")?;
    expand::clamp_negative(&cur, &mut raw, raw_at, &mut w)?;
    if let Some(t) = cur.peek() {
        w.push(Warning {
            line: t.line,
            column: t.column,
            message: format!(
                "{} trailing tokens after the intensity table ignored (first: `{}`)",
                cur.remaining(),
                t.show()
            ),
        });
    }
    expand::check_vertical_c(&cur, &gamma, gt.first(), &mut w)?;

    if (ityp == 1) != (isym == 1) {
        w.push(Warning {
            line: il,
            column: ic,
            message: format!(
                "Ityp = {ityp} contradicts Isym = {isym}; the symmetry indicator Isym is trusted"
            ),
        });
    } else if !(0..=3).contains(&ityp) {
        w.push(Warning {
            line: il,
            column: ic,
            message: format!("Ityp = {ityp} is not 0–3"),
        });
    }

    // The stored planes' angles.
    let horiz: Vec<f64> = (0..planes).map(|k| c_angles[(start + k) % mc]).collect();
    let symmetry = match isym {
        0 => {
            if mc == 1 {
                Symmetry::Rotational
            } else {
                if expand::is_closing(&horiz) {
                    expand::check_duplicate_plane(&raw, ng, mc, ct.last(), &mut w);
                }
                Symmetry::None
            }
        }
        1 => Symmetry::Rotational,
        2 => Symmetry::BilateralC0C180,
        3 => Symmetry::BilateralC90C270,
        _ => Symmetry::Quadrant,
    };
    let expected: Option<(f64, f64)> = match isym {
        2 => Some((0.0, 180.0)),
        3 => Some((270.0, 90.0)),
        4 => Some((0.0, 90.0)),
        _ => None,
    };
    if let Some((a, b)) = expected {
        if horiz[0] != a || horiz[planes - 1] != b {
            w.push(Warning {
                line: sl,
                column: sc,
                message: format!(
                    "Isym {isym} stores C{a}–C{b}, but the stored planes are at C{}–C{}",
                    horiz[0],
                    horiz[planes - 1]
                ),
            });
        }
    }

    // cd/klm → cd with the first lamp set.
    let mut scale = 1.0;
    match lamp_sets.first() {
        Some(s) if s.flux_lm > 0.0 => scale *= s.flux_lm / 1000.0,
        _ => w.push(Warning {
            line: nl,
            column: nc,
            message: "no positive lamp flux in the first lamp set: intensities are kept in cd/klm"
                .into(),
        }),
    }
    if cfli > 0.0 {
        scale *= cfli;
    } else {
        w.push(Warning {
            line: cl,
            column: cc,
            message: format!("conversion factor {cfli} is not positive; 1 used"),
        });
    }
    if n_sets > 1 {
        w.push(Warning {
            line: nl,
            column: nc,
            message: format!("{n_sets} lamp sets: the intensities are converted to candela with the first set's flux"),
        });
    }
    let candela: Vec<f64> = raw.iter().map(|v| v * scale).collect();
    if let Some(k) = candela.iter().position(|v| !v.is_finite()) {
        // Named at the first value whose product overflows (a located, typed error; the
        // product is not representable, so nothing is clamped or dropped).
        let msg = format!(
            "intensity #{} = {:e} times the scale factor {scale:e} (lamp flux / 1000 × conversion factor) overflows the largest \
             double (1.8e308)",
            k + 1,
            raw[k]
        );
        return Err(match cur.token_after(raw_at, k) {
            Some(t) => cur.err_at(&t, msg),
            None => ParseError::new(0, 0, msg),
        });
    }
    Ok(Photometry {
        format: FileFormat::Eulumdat,
        version: Version::Eulumdat,
        photometric_type: PhotometricType::C,
        header: Vec::new(),
        keywords: Vec::new(),
        lamp_sets,
        tilt: Tilt::None,
        tilt_angle_deg: 0.0,
        vertical_angles_deg: gamma,
        horizontal_angles_deg: horiz,
        raw_values: raw,
        intensity_scale: scale,
        candela,
        symmetry,
        ies: None,
        ldt: Some(LdtInfo {
            company,
            ityp,
            isym,
            mc,
            dc,
            ng,
            dg,
            report_number,
            luminaire_name,
            luminaire_number,
            file_name,
            date_user,
            luminaire_dimensions_mm: dims,
            luminous_area_mm: area,
            luminous_area_heights_mm: heights,
            downward_flux_fraction_pct: dff,
            light_output_ratio_pct: lorl,
            conversion_factor: cfli,
            measurement_tilt_deg: tilt_deg,
            direct_ratios,
            c_angles_deg: c_angles,
        }),
        warnings: w,
    })
}
