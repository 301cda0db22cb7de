//! Lines and tokens with their 1-based positions; strict number parsing.

use super::{ParseError, MAX_ANGLES, MIN_ANGLE_STEP_DEG};

/// The bytes without a leading UTF-8 byte-order mark.
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Splits at LF, CRLF and CR. A final line ending does not start an extra (empty) line.
#[cfg(test)]
pub(crate) fn split_lines(bytes: &[u8]) -> Vec<&[u8]> {
    Lines::new(bytes).collect()
}

/// The lines of a byte slice, one at a time (LF, CRLF and CR end a line; a final line ending does
/// not start an extra, empty line). Nothing is allocated: a reader walks a file of any length in
/// constant memory.
#[derive(Debug, Clone)]
pub(crate) struct Lines<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Lines<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, pos: 0 }
    }

    /// The bytes not yet returned (from the start of the next line).
    pub fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos..]
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let b = self.bytes;
        if self.pos >= b.len() {
            return None;
        }
        let start = self.pos;
        let mut i = start;
        while i < b.len() && b[i] != b'\n' && b[i] != b'\r' {
            i += 1;
        }
        let line = &b[start..i];
        if i < b.len() {
            if b[i] == b'\r' && i + 1 < b.len() && b[i + 1] == b'\n' {
                i += 1;
            }
            i += 1;
        }
        self.pos = i;
        Some(line)
    }
}

/// A line decoded lossily (invalid UTF-8 becomes U+FFFD), without surrounding white space.
pub(crate) fn text(line: &[u8]) -> String {
    String::from_utf8_lossy(line).trim().to_string()
}

/// Longest excerpt of a file's text that a message quotes, in characters.
pub(crate) const EXCERPT_CHARS: usize = 40;

/// Bytes of a file for a message: decoded lossily, at most [`EXCERPT_CHARS`] characters (then
/// `…`), control and other non-printable characters escaped (`\n`, `\u{1b}`), so that a message
/// never carries more than a short, harmless piece of what was read.
pub(crate) fn excerpt(bytes: &[u8]) -> String {
    // Never decode more than needed: 4 bytes per character at most.
    let head = &bytes[..bytes.len().min(4 * EXCERPT_CHARS + 4)];
    let s = String::from_utf8_lossy(head);
    let mut out: String = s.chars().take(EXCERPT_CHARS).collect();
    let cut = s.chars().count() > EXCERPT_CHARS || head.len() < bytes.len();
    out = out.escape_debug().to_string();
    if cut {
        out.push('…');
    }
    out
}

/// A token: a run of non-separator bytes, with its 1-based line and byte column.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Token<'a> {
    pub text: &'a [u8],
    pub line: usize,
    pub column: usize,
}

impl Token<'_> {
    /// The token for messages: see [`excerpt`].
    pub fn show(&self) -> String {
        excerpt(self.text)
    }
}

fn is_separator(b: u8, comma: bool) -> bool {
    matches!(b, b' ' | b'\t' | 0x0B | 0x0C) || (comma && b == b',')
}

/// The tokens of `bytes`, whose first line has 1-based number `first_line` (the tokens a
/// [`Cursor`] yields, collected).
#[cfg(test)]
pub(crate) fn tokenize(bytes: &[u8], first_line: usize, comma: bool) -> Vec<Token<'_>> {
    let mut c = Cursor::new(bytes, first_line, comma, false);
    std::iter::from_fn(|| c.next_token()).collect()
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

/// A cursor over the tokens of a byte slice that reads numbers and reports errors with positions.
///
/// Tokens are found one at a time as they are read (nothing is stored per token or per line), so
/// the memory a reader needs does not grow with data it does not keep, such as trailing tokens
/// after a table.
pub(crate) struct Cursor<'a> {
    bytes: &'a [u8],
    /// Where the next unread byte is.
    at: Mark,
    /// 1-based number of the first line of `bytes`.
    first_line: usize,
    /// A comma separates tokens (IES); otherwise it is part of a token (EULUMDAT).
    comma: bool,
    decimal_comma: bool,
    /// Prefix for messages (e.g. the TILT file name).
    pub context: String,
}

/// A place in a [`Cursor`]'s bytes: offset, 1-based line there and the offset that line starts at.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mark {
    pos: usize,
    line: usize,
    line_start: usize,
}

impl<'a> Cursor<'a> {
    /// The tokens of `bytes`, whose first line is line `first_line` of the file. With `comma`, a
    /// comma separates tokens (IES); otherwise it is part of the token (EULUMDAT decimal comma).
    pub fn new(bytes: &'a [u8], first_line: usize, comma: bool, decimal_comma: bool) -> Self {
        Self {
            bytes,
            at: Mark {
                pos: 0,
                line: first_line,
                line_start: 0,
            },
            first_line,
            comma,
            decimal_comma,
            context: String::new(),
        }
    }

    /// The next token from `m` and the mark after it, or `None` at the end.
    fn scan(&self, m: Mark) -> Option<(Token<'a>, Mark)> {
        let b = self.bytes;
        let Mark {
            pos: mut i,
            mut line,
            mut line_start,
        } = m;
        while i < b.len() {
            match b[i] {
                b'\n' => {
                    i += 1;
                    line += 1;
                    line_start = i;
                }
                b'\r' => {
                    i += 1;
                    if i < b.len() && b[i] == b'\n' {
                        i += 1;
                    }
                    line += 1;
                    line_start = i;
                }
                c if is_separator(c, self.comma) => i += 1,
                _ => {
                    let s = i;
                    while i < b.len()
                        && !is_separator(b[i], self.comma)
                        && b[i] != b'\n'
                        && b[i] != b'\r'
                    {
                        i += 1;
                    }
                    let t = Token {
                        text: &b[s..i],
                        line,
                        column: s - line_start + 1,
                    };
                    let after = Mark {
                        pos: i,
                        line,
                        line_start,
                    };
                    return Some((t, after));
                }
            }
        }
        None
    }

    /// The `k`-th token (0-based) from mark `m`, found again by scanning (for messages about
    /// values that were read without keeping their tokens).
    pub fn token_after(&self, m: Mark, k: usize) -> Option<Token<'a>> {
        let mut m = m;
        for _ in 0..k {
            m = self.scan(m)?.1;
        }
        self.scan(m).map(|(t, _)| t)
    }

    /// The next token, consumed.
    #[cfg(test)]
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        let (t, m) = self.scan(self.at)?;
        self.at = m;
        Some(t)
    }

    /// The number of tokens left (a scan to the end: for messages and warnings).
    pub fn remaining(&self) -> usize {
        let mut m = self.at;
        let mut n = 0;
        while let Some((_, next)) = self.scan(m) {
            n += 1;
            m = next;
        }
        n
    }

    /// True when at least `n` tokens are left (scans at most `n` tokens).
    pub fn has_at_least(&self, n: usize) -> bool {
        let mut m = self.at;
        for _ in 0..n {
            match self.scan(m) {
                Some((_, next)) => m = next,
                None => return false,
            }
        }
        true
    }

    /// The position reported for "unexpected end of file": just after the last byte of the last
    /// line (a scan of the whole slice, on that error path only).
    pub fn end(&self) -> (usize, usize) {
        let mut n = 0;
        let mut last = None;
        for l in Lines::new(self.bytes) {
            n += 1;
            last = Some(l.len());
        }
        match last {
            Some(len) => (self.first_line + n - 1, len + 1),
            None => (self.first_line.max(1), 1),
        }
    }

    /// The next token, without consuming it.
    pub fn peek(&self) -> Option<Token<'a>> {
        self.scan(self.at).map(|(t, _)| t)
    }

    pub fn err_at(&self, t: &Token, msg: impl Into<String>) -> ParseError {
        ParseError::new(t.line, t.column, format!("{}{}", self.context, msg.into()))
    }

    fn eof(&self, msg: String) -> ParseError {
        let (l, c) = self.end();
        ParseError::new(l, c, format!("{}{msg}", self.context))
    }

    /// The next token as a number.
    pub fn number(&mut self, what: &str) -> Result<(f64, Token<'a>), ParseError> {
        let Some((t, m)) = self.scan(self.at) else {
            return Err(self.eof(format!(
                "unexpected end of file: expected a number ({what})"
            )));
        };
        match parse_number(t.text, self.decimal_comma) {
            Some(v) => {
                self.at = m;
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

    fn check_left(&self, n: usize, what: &str) -> Result<(), ParseError> {
        if self.has_at_least(n) {
            return Ok(());
        }
        Err(self.eof(format!(
            "unexpected end of file: {n} {what} expected, only {} values follow",
            self.remaining()
        )))
    }

    /// `n` numbers with their tokens, after checking that at least `n` tokens remain (so nothing
    /// is allocated for tokens that are not there).
    pub fn numbers(
        &mut self,
        n: usize,
        what: &str,
    ) -> Result<(Vec<f64>, Vec<Token<'a>>), ParseError> {
        self.check_left(n, what)?;
        let mut v = Vec::with_capacity(n);
        let mut tk = Vec::with_capacity(n);
        for k in 0..n {
            let (x, t) = self.number(&format!("{what} #{}", k + 1))?;
            v.push(x);
            tk.push(t);
        }
        Ok((v, tk))
    }

    /// `n` numbers without their tokens (8 bytes per value: for the large tables), and the mark
    /// before the first; [`Cursor::token_after`] finds a value's token again when a message needs
    /// it.
    pub fn values(&mut self, n: usize, what: &str) -> Result<(Vec<f64>, Mark), ParseError> {
        self.check_left(n, what)?;
        let start = self.at;
        let mut v = Vec::with_capacity(n);
        for k in 0..n {
            match self.scan(self.at) {
                Some((t, m)) => match parse_number(t.text, self.decimal_comma) {
                    Some(x) => {
                        v.push(x);
                        self.at = m;
                    }
                    None => {
                        return Err(self.err_at(
                            &t,
                            format!(
                                "expected a number ({what} #{}), found `{}`",
                                k + 1,
                                t.show()
                            ),
                        ))
                    }
                },
                None => {
                    return Err(self.eof(format!(
                        "unexpected end of file: expected a number ({what} #{})",
                        k + 1
                    )))
                }
            }
        }
        Ok((v, start))
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
        let toks = tokenize(b" 1,2\t3\n  x", 5, true);
        let pos: Vec<_> = toks.iter().map(|t| (t.line, t.column)).collect();
        assert_eq!(pos, vec![(5, 2), (5, 4), (5, 6), (6, 3)]);
        assert_eq!(strip_bom(b"\xEF\xBB\xBFab"), b"ab");
    }
}
