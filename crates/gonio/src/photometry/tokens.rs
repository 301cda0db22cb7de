//! Lines and tokens with their 1-based positions; strict number parsing.

use super::{ParseError, MAX_ANGLES, MIN_ANGLE_STEP_DEG};

/// The bytes without a leading UTF-8 byte-order mark.
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Splits at LF, CRLF and CR. A final line ending does not start an extra (empty) line.
pub(crate) fn split_lines(bytes: &[u8]) -> Vec<&[u8]> {
    let mut lines = Vec::new();
    let mut start = 0;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => {
                lines.push(&bytes[start..i]);
                i += 1;
                start = i;
            }
            b'\r' => {
                lines.push(&bytes[start..i]);
                i += 1;
                if i < bytes.len() && bytes[i] == b'\n' {
                    i += 1;
                }
                start = i;
            }
            _ => i += 1,
        }
    }
    if start < bytes.len() {
        lines.push(&bytes[start..]);
    }
    lines
}

/// A line decoded lossily (invalid UTF-8 becomes U+FFFD), without surrounding white space.
pub(crate) fn text(line: &[u8]) -> String {
    String::from_utf8_lossy(line).trim().to_string()
}

/// A token: a run of non-separator bytes, with its 1-based line and byte column.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Token<'a> {
    pub text: &'a [u8],
    pub line: usize,
    pub column: usize,
}

impl Token<'_> {
    /// The token for messages: lossy, at most 40 characters.
    pub fn show(&self) -> String {
        let s = String::from_utf8_lossy(self.text);
        let mut out: String = s.chars().take(40).collect();
        if s.chars().count() > 40 {
            out.push('…');
        }
        out.escape_debug().to_string()
    }
}

fn is_separator(b: u8, comma: bool) -> bool {
    matches!(b, b' ' | b'\t' | 0x0B | 0x0C) || (comma && b == b',')
}

/// The tokens of `lines`, the first of which has 1-based number `first_line`. With `comma`, a
/// comma separates tokens (IES); otherwise it is part of the token (EULUMDAT decimal comma).
pub(crate) fn tokenize<'a>(lines: &[&'a [u8]], first_line: usize, comma: bool) -> Vec<Token<'a>> {
    let mut out = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let mut i = 0;
        while i < line.len() {
            if is_separator(line[i], comma) {
                i += 1;
                continue;
            }
            let s = i;
            while i < line.len() && !is_separator(line[i], comma) {
                i += 1;
            }
            out.push(Token {
                text: &line[s..i],
                line: first_line + k,
                column: s + 1,
            });
        }
    }
    out
}

/// Parses a decimal number: optional sign, digits with an optional decimal point (at least one
/// digit), optional exponent `e`/`E` with optional sign and digits. With `decimal_comma`, a comma
/// may stand for the decimal point. No `inf`, `nan`, hex or digit separators; the result must be
/// finite.
pub(crate) fn parse_number(t: &[u8], decimal_comma: bool) -> Option<f64> {
    if t.is_empty() {
        return None;
    }
    let n = t.len();
    let mut i = 0;
    let mut digits = 0;
    if t[0] == b'+' || t[0] == b'-' {
        i = 1;
    }
    while i < n && t[i].is_ascii_digit() {
        i += 1;
        digits += 1;
    }
    if i < n && (t[i] == b'.' || (decimal_comma && t[i] == b',')) {
        i += 1;
        while i < n && t[i].is_ascii_digit() {
            i += 1;
            digits += 1;
        }
    }
    if digits == 0 {
        return None;
    }
    if i < n && (t[i] == b'e' || t[i] == b'E') {
        i += 1;
        if i < n && (t[i] == b'+' || t[i] == b'-') {
            i += 1;
        }
        let s = i;
        while i < n && t[i].is_ascii_digit() {
            i += 1;
        }
        if i == s {
            return None;
        }
    }
    if i != n {
        return None;
    }
    // Only ASCII digits, signs, '.', ',' and 'e'/'E' are left: replace the decimal comma.
    let s: String = t
        .iter()
        .map(|&b| if b == b',' { '.' } else { b as char })
        .collect();
    let v: f64 = s.parse().ok()?;
    v.is_finite().then_some(v)
}

/// A cursor over tokens that reads numbers and reports errors with positions.
pub(crate) struct Cursor<'a> {
    toks: Vec<Token<'a>>,
    pos: usize,
    /// Position reported for "unexpected end of file" (line, column).
    end: (usize, usize),
    decimal_comma: bool,
    /// Prefix for messages (e.g. the TILT file name).
    pub context: String,
}

impl<'a> Cursor<'a> {
    pub fn new(toks: Vec<Token<'a>>, end: (usize, usize), decimal_comma: bool) -> Self {
        Self {
            toks,
            pos: 0,
            end,
            decimal_comma,
            context: String::new(),
        }
    }

    pub fn remaining(&self) -> usize {
        self.toks.len() - self.pos
    }

    /// The next token, without consuming it.
    pub fn peek(&self) -> Option<Token<'a>> {
        self.toks.get(self.pos).copied()
    }

    pub fn err_at(&self, t: &Token, msg: impl Into<String>) -> ParseError {
        ParseError::new(t.line, t.column, format!("{}{}", self.context, msg.into()))
    }

    /// The next token as a number.
    pub fn number(&mut self, what: &str) -> Result<(f64, Token<'a>), ParseError> {
        let Some(t) = self.toks.get(self.pos).copied() else {
            return Err(ParseError::new(
                self.end.0,
                self.end.1,
                format!(
                    "{}unexpected end of file: expected a number ({what})",
                    self.context
                ),
            ));
        };
        match parse_number(t.text, self.decimal_comma) {
            Some(v) => {
                self.pos += 1;
                Ok((v, t))
            }
            None => Err(self.err_at(
                &t,
                format!("expected a number ({what}), found `{}`", t.show()),
            )),
        }
    }

    /// The next token as an integer in `[min, max]` (a number with a zero fractional part, such
    /// as `3` or `3.0`).
    pub fn integer(
        &mut self,
        what: &str,
        min: i64,
        max: i64,
    ) -> Result<(i64, Token<'a>), ParseError> {
        let (v, t) = self.number(what)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(self.err_at(
                &t,
                format!(
                    "{what} must be an integer from {min} to {max}, found `{}`",
                    t.show()
                ),
            ));
        }
        Ok((v as i64, t))
    }

    /// A count of angles: an integer in 1..=MAX_ANGLES.
    pub fn count(&mut self, what: &str) -> Result<(usize, Token<'a>), ParseError> {
        let (v, t) = self.integer(what, 1, MAX_ANGLES as i64)?;
        Ok((v as usize, t))
    }

    /// `n` numbers, after checking that at least `n` tokens remain (so nothing is allocated for
    /// tokens that are not there).
    pub fn numbers(
        &mut self,
        n: usize,
        what: &str,
    ) -> Result<(Vec<f64>, Vec<Token<'a>>), ParseError> {
        if self.remaining() < n {
            return Err(ParseError::new(
                self.end.0,
                self.end.1,
                format!(
                    "{}unexpected end of file: {n} {what} expected, only {} values follow",
                    self.context,
                    self.remaining()
                ),
            ));
        }
        let mut v = Vec::with_capacity(n);
        let mut tk = Vec::with_capacity(n);
        for k in 0..n {
            let (x, t) = self.number(&format!("{what} #{}", k + 1))?;
            v.push(x);
            tk.push(t);
        }
        Ok((v, tk))
    }
}

/// The position just after the last byte of the last line (for end-of-file errors).
pub(crate) fn end_position(lines: &[&[u8]], first_line: usize) -> (usize, usize) {
    match lines.last() {
        Some(l) => (first_line + lines.len() - 1, l.len() + 1),
        None => (first_line.max(1), 1),
    }
}

/// Checks that angles are strictly increasing and within `[lo, hi]`; the error names the token.
pub(crate) fn check_angles(
    cur: &Cursor,
    angles: &[f64],
    toks: &[Token],
    what: &str,
    lo: f64,
    hi: f64,
) -> Result<(), ParseError> {
    for (k, (&a, t)) in angles.iter().zip(toks).enumerate() {
        if a < lo || a > hi {
            return Err(cur.err_at(
                t,
                format!("{what} #{} = {a}° is outside [{lo}°, {hi}°]", k + 1),
            ));
        }
        if k > 0 && a - angles[k - 1] < MIN_ANGLE_STEP_DEG {
            return Err(cur.err_at(
                t,
                format!(
                    "{what}s must be strictly increasing (by at least {MIN_ANGLE_STEP_DEG}°), \
                     but #{} = {a}° follows {}°",
                    k + 1,
                    angles[k - 1]
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        let ok = |s: &str, v: f64| assert_eq!(parse_number(s.as_bytes(), false), Some(v), "{s}");
        ok("1", 1.0);
        ok("-2.5", -2.5);
        ok("+.5", 0.5);
        ok("5.", 5.0);
        ok("1e3", 1000.0);
        ok("1.5E-2", 0.015);
        ok("-0", 0.0);
        for bad in [
            "", "-", ".", "e5", "1e", "1e+", "inf", "NaN", "1,5", "0x10", "1_000", "1e999",
            "1.2.3", "--1", "END", "\u{1a}",
        ] {
            assert_eq!(parse_number(bad.as_bytes(), false), None, "{bad:?}");
        }
        assert_eq!(parse_number(b"1,5", true), Some(1.5));
        assert_eq!(parse_number(b"1,5,3", true), None);
    }

    #[test]
    fn line_endings_and_positions() {
        let lines = split_lines(b"a b\r\nc\rd\n\ne");
        assert_eq!(lines, vec![&b"a b"[..], b"c", b"d", b"", b"e"]);
        assert_eq!(split_lines(b"x\n").len(), 1);
        let toks = tokenize(&split_lines(b" 1,2\t3\n  x"), 5, true);
        let pos: Vec<_> = toks.iter().map(|t| (t.line, t.column)).collect();
        assert_eq!(pos, vec![(5, 2), (5, 4), (5, 6), (6, 3)]);
        assert_eq!(strip_bom(b"\xEF\xBB\xBFab"), b"ab");
    }
}
