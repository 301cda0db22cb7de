//! IES LM-63 reader (1986, 1991, 1995, 2002, 2019 and the variants met in practice).

use super::tokens::{check_angles, excerpt, strip_bom, text, Cursor, Lines, Mark, Token};
use super::{
    validate, IesInfo, Keyword, LampSet, ParseError, PhotometricType, Photometry, Tilt,
    TiltResolver, TiltTable, Version, Warning, MAX_ANGLES, MAX_HEADER_LINES,
};
use crate::diagram::MAX_NODES;

/// Recognises the version line; `None` for LM-63-1986 (no version line).
fn version_of(first: &str) -> Option<(Version, Option<String>)> {
    let compact: String = first
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    let v = match compact.as_str() {
        "IESNA91" => (Version::Ies1991, None),
        "IESNA95" => (
            Version::Ies1995,
            Some("non-standard version line `IESNA95` read as LM-63-1995".to_string()),
        ),
        "IESNA:LM-63-1995" => (Version::Ies1995, None),
        "IESNA:LM-63-2002" => (Version::Ies2002, None),
        "IES:LM-63-2019" => (Version::Ies2019, None),
        "IESNA:LM-63-2019" | "IES:LM-63-2002" | "IES:LM-63-1995" => {
            let v = if compact.ends_with("2019") {
                Version::Ies2019
            } else if compact.ends_with("2002") {
                Version::Ies2002
            } else {
                Version::Ies1995
            };
            (
                v,
                Some(format!(
                    "non-standard version line `{}` read as {v}",
                    excerpt(first.as_bytes())
                )),
            )
        }
        c if c.starts_with("IESNA") || c.starts_with("IES:") => (
            Version::Ies2002,
            Some(format!(
                "unknown version line `{}`; read with the LM-63-2002 rules",
                excerpt(first.as_bytes())
            )),
        ),
        _ => return None,
    };
    Some(v)
}

/// If `line` is a TILT line, the byte column (1-based) where its value starts and the value.
fn tilt_line(line: &[u8]) -> Option<(usize, String)> {
    let lead = line.iter().take_while(|b| b.is_ascii_whitespace()).count();
    let rest = &line[lead..];
    if rest.len() < 4 || !rest[..4].eq_ignore_ascii_case(b"TILT") {
        return None;
    }
    let after = &rest[4..];
    let sp = after
        .iter()
        .take_while(|b| **b == b' ' || **b == b'\t')
        .count();
    if after.get(sp) != Some(&b'=') {
        return None;
    }
    let val = &after[sp + 1..];
    let vs = val
        .iter()
        .take_while(|b| **b == b' ' || **b == b'\t')
        .count();
    Some((lead + 4 + sp + 1 + vs + 1, text(val)))
}

/// Reads an IES LM-63 file in its four steps: [`read_header`] (version line, keywords, the `TILT=`
/// line), [`read_tilt`] and [`read_fields`] (the thirteen numbers of the luminaire line),
/// [`read_angles`] (counts against caps and against what is present, then the angles and their
/// ranges), [`read_values`] (the candela table), then the validation of the whole
/// ([`validate::classify`]: symmetry and vertical range) and the intensity scale
/// ([`intensity_scale`]). Warnings come in the order of the file.
pub(crate) fn read_ies(
    bytes: &[u8],
    resolver: &dyn TiltResolver,
) -> Result<Photometry, ParseError> {
    let mut warnings = Vec::new();
    let head = read_header(bytes, &mut warnings)?;
    let mut cur = Cursor::new(head.rest, head.tilt_line + 1, true, false);
    let tilt = read_tilt(&mut cur, &head, resolver, &mut warnings)?;
    let fields = read_fields(&mut cur, head.version, &mut warnings)?;
    let angles = read_angles(&mut cur, &fields)?;
    let (raw, raw_at) = read_values(&mut cur, angles.values, &mut warnings)?;
    let symmetry = validate::classify(
        angles.photometric_type,
        &angles.vert,
        &angles.horiz,
        &raw,
        (angles.vt.first(), angles.vt.last()),
        (angles.ht.first(), angles.ht.last()),
        &cur,
        &mut warnings,
    )?;
    let (scale, candela) =
        intensity_scale(&fields, &head, &tilt, (&raw, &cur, raw_at), &mut warnings)?;

    let lamp_description = head
        .keywords
        .iter()
        .find(|k| k.key.eq_ignore_ascii_case("LAMP"))
        .map(|k| k.value.clone())
        .unwrap_or_default();
    let flux = if fields.lumens_per_lamp > 0.0 {
        fields.lamps as f64 * fields.lumens_per_lamp
    } else {
        -1.0
    };
    Ok(Photometry {
        format: super::FileFormat::Ies,
        version: head.version,
        photometric_type: angles.photometric_type,
        header: head.header,
        keywords: head.keywords,
        lamp_sets: vec![LampSet {
            count: fields.lamps,
            description: lamp_description,
            flux_lm: flux,
            color: String::new(),
            color_rendering: String::new(),
            watts: fields.input_watts,
        }],
        tilt,
        tilt_angle_deg: TILT_ANGLE_DEG,
        vertical_angles_deg: angles.vert,
        horizontal_angles_deg: angles.horiz,
        raw_values: raw,
        intensity_scale: scale,
        candela,
        symmetry,
        ies: Some(IesInfo {
            version_line: head.version_line,
            lamps: fields.lamps,
            lumens_per_lamp: fields.lumens_per_lamp,
            multiplier: fields.multiplier,
            units_type: fields.units_type as i64,
            width: fields.width,
            length: fields.length,
            height: fields.height,
            ballast_factor: fields.ballast_factor,
            second_ballast_field: fields.second,
            input_watts: fields.input_watts,
        }),
        ldt: None,
        warnings,
    })
}

/// The lamp tilt the intensities are given for: the TILT factor is read at this angle.
const TILT_ANGLE_DEG: f64 = 0.0;

/// What precedes the numbers of an IES file: the version, the keywords and free text, and the
/// `TILT=` line with the bytes after it.
struct Header<'a> {
    version: Version,
    /// The version line as written (empty for LM-63-1986).
    version_line: String,
    /// Free-text header lines.
    header: Vec<String>,
    keywords: Vec<Keyword>,
    /// 1-based line of the `TILT=` line.
    tilt_line: usize,
    /// 1-based byte column of its value.
    tilt_col: usize,
    /// Its value (`NONE`, `INCLUDE` or a file name).
    tilt_value: String,
    /// The bytes after the `TILT=` line.
    rest: &'a [u8],
}

/// Step 1: the version line, the keyword lines (with `[MORE]`) and free text, up to the `TILT=`
/// line. Lines are taken one at a time: nothing is stored per line or per token of the file.
fn read_header<'a>(bytes: &'a [u8], warnings: &mut Vec<Warning>) -> Result<Header<'a>, ParseError> {
    let mut lines = Lines::new(strip_bom(bytes));
    let Some(first_line) = lines.clone().next() else {
        return Err(ParseError::new(0, 0, "the file is empty"));
    };
    let first = text(first_line);
    let (version, version_line, header_start) = match version_of(&first) {
        Some((v, w)) => {
            if let Some(w) = w {
                warnings.push(Warning {
                    line: 1,
                    column: 1,
                    message: w,
                });
            }
            (v, first.clone(), 1)
        }
        None => (Version::Ies1986, String::new(), 0),
    };

    let mut header = Vec::new();
    let mut keywords: Vec<Keyword> = Vec::new();
    let mut tilt_at = None;
    if header_start == 1 {
        lines.next();
    }
    for (k, raw) in lines
        .by_ref()
        .enumerate()
        .map(|(k, l)| (k + header_start, l))
    {
        let lno = k + 1;
        if k - header_start >= MAX_HEADER_LINES {
            return Err(ParseError::new(
                lno,
                1,
                format!(
                    "no `TILT=` line within the first {MAX_HEADER_LINES} header lines: \
                     this is not an IES LM-63 file"
                ),
            ));
        }
        if let Some((col, value)) = tilt_line(raw) {
            tilt_at = Some((k, col, value));
            break;
        }
        let t = text(raw);
        if t.is_empty() {
            continue;
        }
        if version != Version::Ies1986 && t.starts_with('[') {
            if let Some(close) = t.find(']') {
                let key = t[1..close].trim().to_string();
                let value = t[close + 1..].trim().to_string();
                if key.eq_ignore_ascii_case("MORE") {
                    match keywords.last_mut() {
                        Some(last) => {
                            last.value.push('\n');
                            last.value.push_str(&value);
                        }
                        None => warnings.push(Warning {
                            line: lno,
                            column: 1,
                            message: "[MORE] without a preceding keyword (ignored)".into(),
                        }),
                    }
                } else {
                    keywords.push(Keyword {
                        key,
                        value,
                        line: lno,
                    });
                }
                continue;
            }
        }
        if version != Version::Ies1986 {
            warnings.push(Warning {
                line: lno,
                column: 1,
                message: format!(
                    "header line is not a keyword; kept as free text: `{}`",
                    excerpt(t.as_bytes())
                ),
            });
        }
        header.push(t);
    }
    let Some((tilt_idx, tilt_col, tilt_value)) = tilt_at else {
        return Err(ParseError::new(
            0,
            0,
            "no `TILT=` line found: this is not an IES LM-63 file",
        ));
    };
    Ok(Header {
        version,
        version_line,
        header,
        keywords,
        tilt_line: tilt_idx + 1,
        tilt_col,
        tilt_value,
        rest: lines.rest(),
    })
}

/// Step 2: the tilt: none, a table that follows the `TILT=INCLUDE` line, or a table in the file
/// the `TILT=` line names (read through `resolver`).
fn read_tilt(
    cur: &mut Cursor,
    head: &Header,
    resolver: &dyn TiltResolver,
    warnings: &mut Vec<Warning>,
) -> Result<Tilt, ParseError> {
    let (tilt_line_no, tilt_col) = (head.tilt_line, head.tilt_col);
    Ok(match head.tilt_value.to_ascii_uppercase().as_str() {
        "NONE" => Tilt::None,
        "INCLUDE" => Tilt::Include(read_tilt_table(cur)?),
        "" => {
            return Err(ParseError::new(
                tilt_line_no,
                tilt_col,
                "TILT= has no value (expected NONE, INCLUDE or a file name)",
            ))
        }
        _ => {
            let name = head.tilt_value.clone();
            let shown = excerpt(name.as_bytes());
            let bytes = resolver.resolve(&name).map_err(|m| {
                ParseError::new(tilt_line_no, tilt_col, format!("TILT file `{shown}`: {m}"))
            })?;
            let mut tc = Cursor::new(strip_bom(&bytes), 1, true, false);
            let table = read_tilt_table(&mut tc).map_err(|e| {
                ParseError::new(
                    tilt_line_no,
                    tilt_col,
                    format!(
                        "in TILT file `{shown}` at {}:{}: {}",
                        e.line, e.column, e.message
                    ),
                )
            })?;
            if let Some(t) = tc.peek() {
                warnings.push(Warning {
                    line: tilt_line_no,
                    column: tilt_col,
                    message: format!(
                        "TILT file `{shown}`: {} trailing tokens after the table ignored (first `{}` at {}:{})",
                        tc.remaining(),
                        t.show(),
                        t.line,
                        t.column
                    ),
                });
            }
            Tilt::File { name, table }
        }
    })
}

/// The thirteen numbers after the tilt: lamps, the scale, the counts, the type and the opening.
struct Fields<'a> {
    lamps: i64,
    lumens_per_lamp: f64,
    multiplier: f64,
    n_v: usize,
    /// The token of the number of vertical angles (where count errors point).
    nvt: Token<'a>,
    n_h: usize,
    ptype: i64,
    units_type: f64,
    width: f64,
    length: f64,
    height: f64,
    ballast_factor: f64,
    bt: Token<'a>,
    /// The second ballast field (ballast-lamp photometric factor before LM-63-2002).
    second: f64,
    st: Token<'a>,
    input_watts: f64,
}

/// Step 3: the luminaire's numbers, each checked on its own (a positive multiplier, a photometric
/// type 1–3; a units type other than 1 or 2 is a warning).
fn read_fields<'a>(
    cur: &mut Cursor<'a>,
    version: Version,
    warnings: &mut Vec<Warning>,
) -> Result<Fields<'a>, ParseError> {
    let (lamps, _) = cur.integer("number of lamps", i64::MIN / 2, i64::MAX / 2)?;
    let (lumens_per_lamp, _) = cur.number("lumens per lamp")?;
    let (multiplier, mt) = cur.number("candela multiplier")?;
    if multiplier <= 0.0 {
        return Err(cur.err_at(
            &mt,
            format!("the candela multiplier must be positive, found {multiplier}"),
        ));
    }
    let (n_v, nvt) = cur.count("number of vertical angles")?;
    let (n_h, _) = cur.count("number of horizontal angles")?;
    let (ptype, _) = cur.integer("photometric type", 1, 3)?;
    let (units_type, ut) = cur.number("units type")?;
    if units_type != 1.0 && units_type != 2.0 {
        warnings.push(Warning {
            line: ut.line,
            column: ut.column,
            message: format!("units type {units_type} is neither 1 (feet) nor 2 (metres)"),
        });
    }
    let (width, _) = cur.number("luminous opening width")?;
    let (length, _) = cur.number("luminous opening length")?;
    let (height, _) = cur.number("luminous opening height")?;
    let (ballast_factor, bt) = cur.number("ballast factor")?;
    let (second, st) = cur.number(match version {
        Version::Ies2019 => "file generation type",
        Version::Ies2002 => "future use field",
        _ => "ballast-lamp photometric factor",
    })?;
    let (input_watts, _) = cur.number("input watts")?;
    Ok(Fields {
        lamps,
        lumens_per_lamp,
        multiplier,
        n_v,
        nvt,
        n_h,
        ptype,
        units_type,
        width,
        length,
        height,
        ballast_factor,
        bt,
        second,
        st,
        input_watts,
    })
}

/// The angles of the table, with their tokens (where errors point).
struct Angles<'a> {
    photometric_type: PhotometricType,
    vert: Vec<f64>,
    vt: Vec<Token<'a>>,
    horiz: Vec<f64>,
    ht: Vec<Token<'a>>,
    /// Number of candela values that follow (vertical × horizontal).
    values: usize,
}

/// Step 4: the counts against [`MAX_NODES`] and against what is present (before anything
/// proportional to them is allocated), then the vertical and horizontal angles, each in the range
/// of its photometric type and strictly increasing.
fn read_angles<'a>(cur: &mut Cursor<'a>, f: &Fields<'a>) -> Result<Angles<'a>, ParseError> {
    let (n_v, n_h) = (f.n_v, f.n_h);
    let values = n_v
        .checked_mul(n_h)
        .filter(|&c| c <= MAX_NODES)
        .ok_or_else(|| {
            cur.err_at(
                &f.nvt,
                format!("{n_v} × {n_h} candela values exceed the limit of {MAX_NODES}"),
            )
        })?;
    let needed = values + n_v + n_h;
    if !cur.has_at_least(needed) {
        return Err(cur.err_at(
            &f.nvt,
            format!(
                "the file declares {n_v} vertical × {n_h} horizontal angles ({needed} numbers), \
                 but only {} values follow",
                cur.remaining()
            ),
        ));
    }
    let photometric_type = match f.ptype {
        1 => PhotometricType::C,
        2 => PhotometricType::B,
        _ => PhotometricType::A,
    };
    let (vert, vt) = cur.numbers(n_v, "vertical angle")?;
    let (horiz, ht) = cur.numbers(n_h, "horizontal angle")?;
    match photometric_type {
        PhotometricType::C => {
            check_angles(cur, &vert, &vt, "vertical angle", 0.0, 180.0)?;
            // A closing plane at first + 360° is allowed even when the first angle is not 0.
            let hi = if validate::is_closing(&horiz) {
                horiz[0] + 360.0
            } else {
                360.0
            };
            check_angles(cur, &horiz, &ht, "horizontal angle", 0.0, hi)?;
        }
        PhotometricType::B => {
            check_angles(cur, &vert, &vt, "vertical angle", -180.0, 180.0)?;
            check_angles(cur, &horiz, &ht, "horizontal angle", -90.0, 90.0)?;
        }
        PhotometricType::A => {
            check_angles(cur, &vert, &vt, "vertical angle", -90.0, 90.0)?;
            check_angles(cur, &horiz, &ht, "horizontal angle", -180.0, 180.0)?;
        }
    }
    Ok(Angles {
        photometric_type,
        vert,
        vt,
        horiz,
        ht,
        values,
    })
}

/// Step 5: the candela table (round-off negatives clamped with a warning, real ones refused);
/// tokens after it are a warning.
fn read_values(
    cur: &mut Cursor,
    count: usize,
    warnings: &mut Vec<Warning>,
) -> Result<(Vec<f64>, Mark), ParseError> {
    let (mut raw, start) = cur.values(count, "candela value")?;
    validate::clamp_negative(cur, &mut raw, start, warnings)?;
    if let Some(t) = cur.peek() {
        warnings.push(Warning {
            line: t.line,
            column: t.column,
            message: format!(
                "{} trailing tokens after the candela table ignored (first: `{}`)",
                cur.remaining(),
                t.show()
            ),
        });
    }
    Ok((raw, start))
}

/// Step 6: the intensity scale (multiplier × ballast factor × the ballast-lamp factor before
/// LM-63-2002 × the TILT factor at [`TILT_ANGLE_DEG`]; a factor that is not positive counts as 1
/// with a warning) and the candela values it gives, refused if they overflow.
fn intensity_scale(
    f: &Fields,
    head: &Header,
    tilt: &Tilt,
    (raw, cur, start): (&[f64], &Cursor, Mark),
    warnings: &mut Vec<Warning>,
) -> Result<(f64, Vec<f64>), ParseError> {
    let mut scale = f.multiplier;
    // A factor that is not positive counts as 1, with a warning at its token.
    let mut apply = |factor: f64, at: &Token, what: &str| {
        if factor > 0.0 {
            scale *= factor;
        } else {
            warnings.push(Warning {
                line: at.line,
                column: at.column,
                message: format!("{what} {factor} is not positive; 1 used"),
            });
        }
    };
    apply(f.ballast_factor, &f.bt, "ballast factor");
    if matches!(
        head.version,
        Version::Ies1986 | Version::Ies1991 | Version::Ies1995
    ) {
        apply(f.second, &f.st, "ballast-lamp photometric factor");
    }
    if let Some(t) = tilt.table() {
        // The file's factor is kept, 0 included: replacing it would change the light. A factor
        // of 0 leaves no light, which `to_diagram` refuses (zero total power).
        let f = t.factor_at(TILT_ANGLE_DEG);
        scale *= f;
        if f == 0.0 {
            warnings.push(Warning {
                line: head.tilt_line,
                column: head.tilt_col,
                message: "TILT factor at 0° is 0: at this tilt the luminaire emits no light \
                          (every intensity is 0)"
                    .into(),
            });
        }
    }
    let candela: Vec<f64> = raw.iter().map(|v| v * scale).collect();
    if let Some(k) = candela.iter().position(|v| !v.is_finite()) {
        // Named at the first value whose product overflows (a located, typed error; the
        // product is not representable, so nothing is clamped or dropped).
        let msg = format!(
            "intensity #{} = {:e} times the scale factor {scale:e} (multiplier × ballast factor × …) overflows the largest \
             double (1.8e308)",
            k + 1,
            raw[k]
        );
        return Err(match cur.token_after(start, k) {
            Some(t) => cur.err_at(&t, msg),
            None => ParseError::new(0, 0, msg),
        });
    }
    Ok((scale, candela))
}

/// Reads a TILT table: geometry, number of pairs, angles, factors.
fn read_tilt_table(cur: &mut Cursor) -> Result<TiltTable, ParseError> {
    let (geometry, _) = cur.integer("TILT lamp-to-luminaire geometry", 1, 3)?;
    let (n, nt) = cur.integer("number of TILT angles", 0, MAX_ANGLES as i64)?;
    let n = n as usize;
    if !cur.has_at_least(2 * n) {
        return Err(cur.err_at(
            &nt,
            format!(
                "the TILT table declares {n} angles ({} numbers), but only {} values follow",
                2 * n,
                cur.remaining()
            ),
        ));
    }
    let (angles, at) = cur.numbers(n, "TILT angle")?;
    check_angles(cur, &angles, &at, "TILT angle", -180.0, 180.0)?;
    let (factors, ft) = cur.numbers(n, "TILT factor")?;
    for (f, t) in factors.iter().zip(&ft) {
        if *f < 0.0 {
            return Err(cur.err_at(t, format!("TILT factor {f} is negative")));
        }
    }
    Ok(TiltTable {
        geometry: geometry as u8,
        angles_deg: angles,
        factors,
    })
}
