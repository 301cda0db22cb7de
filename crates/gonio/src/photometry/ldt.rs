//! EULUMDAT reader.

use super::tokens::{
    check_angles, excerpt, parse_number, strip_bom, text, Cursor, Lines, Mark, Token,
};
use super::{
    validate, FileFormat, LampSet, LdtInfo, ParseError, PhotometricType, Photometry, Symmetry,
    Tilt, Version, Warning, MAX_ANGLES, MAX_LAMP_SETS,
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

/// Reads an EULUMDAT file in its four steps: [`read_header`] (the 26 + 6·n header lines, one
/// field a line), [`read_angles`] (direct ratios, the stored planes Isym implies, counts against
/// caps and against what is present, the C and γ angles), [`read_values`] (the intensity table),
/// then the validation of the whole ([`validate_table`]: vertical range, Ityp against Isym, the
/// stored planes) and the scale to candela ([`intensity_scale`]). Warnings come in the order of
/// the file.
pub(crate) fn read_ldt(bytes: &[u8]) -> Result<Photometry, ParseError> {
    let bytes = strip_bom(bytes);
    if Lines::new(bytes).all(|l| l.trim_ascii().is_empty()) {
        return Err(ParseError::new(0, 0, "the file is empty"));
    }
    let mut w = Vec::new();
    let (h, rest, first_data_line) = read_header(bytes, &mut w)?;
    let mut cur = Cursor::new(rest, first_data_line, false, true);
    let a = read_angles(&mut cur, &h)?;
    let (raw, raw_at) = read_values(&mut cur, a.values, &mut w)?;
    let (horiz, symmetry) = validate_table(&cur, &h, &a, &raw, &mut w)?;
    let (scale, candela) = intensity_scale(&h, (&raw, &cur, raw_at), &mut w)?;
    Ok(Photometry {
        format: FileFormat::Eulumdat,
        version: Version::Eulumdat,
        photometric_type: PhotometricType::C,
        header: Vec::new(),
        keywords: Vec::new(),
        lamp_sets: h.lamp_sets,
        tilt: Tilt::None,
        tilt_angle_deg: 0.0,
        vertical_angles_deg: a.gamma,
        horizontal_angles_deg: horiz,
        raw_values: raw,
        intensity_scale: scale,
        candela,
        symmetry,
        ies: None,
        ldt: Some(LdtInfo {
            company: h.company,
            ityp: h.ityp.0,
            isym: h.isym.0,
            mc: h.mc.0,
            dc: h.dc,
            ng: h.ng.0,
            dg: h.dg,
            report_number: h.report_number,
            luminaire_name: h.luminaire_name,
            luminaire_number: h.luminaire_number,
            file_name: h.file_name,
            date_user: h.date_user,
            luminaire_dimensions_mm: h.dims,
            luminous_area_mm: h.area,
            luminous_area_heights_mm: h.heights,
            downward_flux_fraction_pct: h.dff,
            light_output_ratio_pct: h.lorl,
            conversion_factor: h.cfli.0,
            measurement_tilt_deg: h.tilt_deg,
            direct_ratios: a.direct_ratios,
            c_angles_deg: a.c_angles,
        }),
        warnings: w,
    })
}

/// A header field with the 1-based (line, column) it was read at (where messages point).
type At<T> = (T, usize, usize);

/// The header lines of an EULUMDAT file (lines 1 to 26 + 6·n).
struct Header {
    company: String,
    ityp: At<i64>,
    isym: At<i64>,
    mc: At<usize>,
    dc: f64,
    ng: At<usize>,
    dg: f64,
    report_number: String,
    luminaire_name: String,
    luminaire_number: String,
    file_name: String,
    date_user: String,
    dims: [f64; 3],
    area: [f64; 2],
    heights: [f64; 4],
    dff: f64,
    lorl: f64,
    cfli: At<f64>,
    tilt_deg: f64,
    /// The number of lamp sets, where it was read.
    n_sets: At<usize>,
    lamp_sets: Vec<LampSet>,
}

/// Step 1: the header, one field a line (fields not needed for the distribution may be empty,
/// read as 0 with a warning). Returns it with the bytes after it and their first line's number.
fn read_header<'a>(
    bytes: &'a [u8],
    w: &mut Vec<Warning>,
) -> Result<(Header, &'a [u8], usize), ParseError> {
    let mut f = Fields {
        bytes,
        lines: Lines::new(bytes),
        next: 0,
    };
    let company = f.text("company identification (line 1)")?;
    let ityp = f.integer("type indicator Ityp", i64::MIN / 2, i64::MAX / 2)?;
    let isym = f.integer("symmetry indicator Isym", 0, 4)?;
    let (mc, mcl, mcc) = f.integer("number of C planes Mc", 1, MAX_ANGLES as i64)?;
    let dc = f.lenient("distance between C planes Dc", w)?;
    let (ng, ngl, ngc) = f.integer("number of γ angles Ng", 1, MAX_ANGLES as i64)?;
    let dg = f.lenient("distance between γ angles Dg", w)?;
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
        *d = f.lenient(what, w)?;
    }
    let mut area = [0.0; 2];
    for (d, what) in area
        .iter_mut()
        .zip(["luminous area length", "luminous area width"])
    {
        *d = f.lenient(what, w)?;
    }
    let mut heights = [0.0; 4];
    for (d, what) in heights.iter_mut().zip([
        "luminous area height C0",
        "luminous area height C90",
        "luminous area height C180",
        "luminous area height C270",
    ]) {
        *d = f.lenient(what, w)?;
    }
    let dff = f.lenient("downward flux fraction DFF", w)?;
    let lorl = f.lenient("light output ratio LORL", w)?;
    let cfli = f.number("conversion factor for luminous intensities")?;
    let tilt_deg = f.lenient("tilt during measurement", w)?;
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
        let watts = f.lenient("wattage including ballast", w)?;
        lamp_sets.push(LampSet {
            count,
            description,
            flux_lm: flux,
            color,
            color_rendering,
            watts,
        });
    }
    let header = Header {
        company,
        ityp,
        isym,
        mc: (mc as usize, mcl, mcc),
        dc,
        ng: (ng as usize, ngl, ngc),
        dg,
        report_number,
        luminaire_name,
        luminaire_number,
        file_name,
        date_user,
        dims,
        area,
        heights,
        dff,
        lorl,
        cfli,
        tilt_deg,
        n_sets: (n_sets, nl, nc),
        lamp_sets,
    };
    // The rest is read as white-space separated numbers (one per line in the standard layout).
    Ok((header, f.lines.rest(), f.next + 1))
}

/// The direct ratios and the angles of the table, with the stored planes Isym implies.
struct Angles<'a> {
    direct_ratios: [f64; 10],
    /// Index (0-based) of the first stored plane among the Mc C angles.
    start: usize,
    /// Number of stored planes.
    planes: usize,
    c_angles: Vec<f64>,
    ct: Vec<Token<'a>>,
    gamma: Vec<f64>,
    gt: Vec<Token<'a>>,
    /// Number of intensity values that follow (planes × Ng).
    values: usize,
}

/// Step 2: the ten direct ratios; the stored planes for Isym (Mc must split as Isym requires);
/// the counts against [`MAX_NODES`] and against what is present (before anything proportional to
/// them is allocated); the C angles in [0°, 360°] and the γ angles in [0°, 180°], each strictly
/// increasing.
fn read_angles<'a>(cur: &mut Cursor<'a>, h: &Header) -> Result<Angles<'a>, ParseError> {
    let ((mc, mcl, mcc), (ng, ngl, ngc), isym) = (h.mc, h.ng, h.isym.0);
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
    check_angles(cur, &c_angles, &ct, "C angle", 0.0, 360.0)?;
    let (gamma, gt) = cur.numbers(ng, "γ angle")?;
    check_angles(cur, &gamma, &gt, "γ angle", 0.0, 180.0)?;
    Ok(Angles {
        direct_ratios,
        start,
        planes,
        c_angles,
        ct,
        gamma,
        gt,
        values,
    })
}

/// Step 3: the intensity table in cd/klm (round-off negatives clamped with a warning, real ones
/// refused); tokens after it are a warning.
fn read_values(
    cur: &mut Cursor,
    count: usize,
    w: &mut Vec<Warning>,
) -> Result<(Vec<f64>, Mark), ParseError> {
    let (mut raw, raw_at) = cur.values(count, "luminous intensity (cd/klm)")?;
    validate::clamp_negative(cur, &mut raw, raw_at, w)?;
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
    Ok((raw, raw_at))
}

/// Step 4: the table as a whole: the γ range ([`validate::check_vertical_c`]), Ityp against Isym,
/// a closing plane that differs from the first, stored planes other than those Isym names.
/// Returns the stored planes' angles and the symmetry.
fn validate_table(
    cur: &Cursor,
    h: &Header,
    a: &Angles,
    raw: &[f64],
    w: &mut Vec<Warning>,
) -> Result<(Vec<f64>, Symmetry), ParseError> {
    let ((ityp, il, ic), (isym, sl, sc), mc, ng) = (h.ityp, h.isym, h.mc.0, h.ng.0);
    validate::check_vertical_c(cur, &a.gamma, a.gt.first(), w)?;

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
    let (start, planes) = (a.start, a.planes);
    let horiz: Vec<f64> = (0..planes).map(|k| a.c_angles[(start + k) % mc]).collect();
    let symmetry = match isym {
        0 => {
            if mc == 1 {
                Symmetry::Rotational
            } else {
                if validate::is_closing(&horiz) {
                    validate::check_duplicate_plane(raw, ng, mc, a.ct.last(), w);
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
    if let Some((lo, hi)) = expected {
        if horiz[0] != lo || horiz[planes - 1] != hi {
            w.push(Warning {
                line: sl,
                column: sc,
                message: format!(
                    "Isym {isym} stores C{lo}–C{hi}, but the stored planes are at C{}–C{}",
                    horiz[0],
                    horiz[planes - 1]
                ),
            });
        }
    }
    Ok((horiz, symmetry))
}

/// Step 5: cd/klm → cd with the first lamp set's flux and the conversion factor (a factor that is
/// not positive counts as 1 with a warning), and the candela values it gives, refused if they
/// overflow.
fn intensity_scale(
    h: &Header,
    (raw, cur, raw_at): (&[f64], &Cursor, Mark),
    w: &mut Vec<Warning>,
) -> Result<(f64, Vec<f64>), ParseError> {
    let ((n_sets, nl, nc), (cfli, cl, cc)) = (h.n_sets, h.cfli);
    let mut scale = 1.0;
    match h.lamp_sets.first() {
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
    Ok((scale, candela))
}
