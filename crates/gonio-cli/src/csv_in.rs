//! Reading numeric columns from a CSV file by header name (`--points`, `--directions`).
//!
//! The first non-empty line is the header; columns are found by name (trimmed, optional double
//! quotes, any letter case); other columns are ignored. Empty lines and lines starting with `#`
//! are skipped. Every error names the file, the line and the 1-based data row.

use anyhow::Context;
use std::io::{BufRead, BufReader, Read};

/// One data row: its 1-based line in the file, its 1-based number among the data rows, and the
/// values of the requested columns in the requested order.
#[derive(Debug, Clone, PartialEq)]
pub struct Row<const K: usize> {
    /// 1-based line of the file.
    pub line: usize,
    /// 1-based data row (the header is not counted).
    pub row: usize,
    /// The values of the requested columns.
    pub values: [f64; K],
}

impl<const K: usize> Row<K> {
    /// `FILE:LINE: row R` — the prefix of every message about this row.
    pub fn locate(&self, file: &str) -> String {
        format!("{file}:{}: row {}", self.line, self.row)
    }
}

/// Reads columns `names` of every data row of `path` (`-` is standard input).
pub fn read_columns<const K: usize>(path: &str, names: [&str; K]) -> anyhow::Result<Vec<Row<K>>> {
    let reader: Box<dyn Read> = if path == "-" {
        Box::new(std::io::stdin())
    } else {
        Box::new(crate::input::open_regular(std::path::Path::new(path), path)?.0)
    };
    let mut reader = BufReader::new(reader);
    let mut index: Option<[usize; K]> = None;
    let mut rows = Vec::new();
    let mut line = String::new();
    let mut line_no = 0usize;
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .with_context(|| format!("cannot read {path}"))?;
        if n == 0 {
            break;
        }
        line_no += 1;
        let mut text = line.trim_end_matches(['\n', '\r']);
        if line_no == 1 {
            text = text.trim_start_matches('\u{feff}');
        }
        if text.trim().is_empty() || text.trim_start().starts_with('#') {
            continue;
        }
        let fields = split_fields(text).map_err(|col| {
            anyhow::anyhow!("{path}:{line_no}:{col}: a quoted field is not closed")
        })?;
        let fields: Vec<&str> = fields.iter().map(|f| f.trim()).collect();
        match &index {
            None => {
                let mut idx = [0usize; K];
                for (k, name) in names.iter().enumerate() {
                    idx[k] = fields
                        .iter()
                        .position(|f| f.eq_ignore_ascii_case(name))
                        .ok_or_else(|| {
                            anyhow::anyhow!(
                                "{path}:{line_no}: the header has no column `{name}` (expected columns {})",
                                names.join(",")
                            )
                        })?;
                }
                index = Some(idx);
            }
            Some(idx) => {
                let row = rows.len() + 1;
                let mut values = [0.0; K];
                for k in 0..K {
                    let field = fields.get(idx[k]).ok_or_else(|| {
                        anyhow::anyhow!(
                            "{path}:{line_no}: row {row}: has {} fields, no column `{}`",
                            fields.len(),
                            names[k]
                        )
                    })?;
                    values[k] = field.parse::<f64>().map_err(|_| {
                        anyhow::anyhow!(
                            "{path}:{line_no}: row {row}: {} = `{field}` is not a number",
                            names[k]
                        )
                    })?;
                    if values[k].is_infinite() && !field.to_ascii_lowercase().contains("inf") {
                        anyhow::bail!(
                            "{path}:{line_no}: row {row}: {} = `{field}` is out of the range of a \
                             double-precision number",
                            names[k]
                        );
                    }
                }
                rows.push(Row {
                    line: line_no,
                    row,
                    values,
                });
            }
        }
    }
    if index.is_none() {
        anyhow::bail!(
            "{path}: the file is empty; expected a header with columns {}",
            names.join(",")
        );
    }
    Ok(rows)
}

/// Splits one CSV line into fields (RFC 4180): a field that starts with `"` (after spaces) runs to
/// the matching closing quote, with `""` standing for one quote, so `"0.1,0.2"` is one field.
/// Returns the fields unquoted, or the 1-based column of an unclosed quote.
pub fn split_fields(line: &str) -> Result<Vec<String>, usize> {
    let mut fields = Vec::new();
    let mut chars = line.char_indices().peekable();
    loop {
        let mut field = String::new();
        // Leading spaces, then an optional quoted part.
        while let Some(&(_, c)) = chars.peek() {
            if c == ' ' || c == '\t' {
                field.push(c);
                chars.next();
            } else {
                break;
            }
        }
        if let Some(&(start, '"')) = chars.peek() {
            chars.next();
            field.clear();
            let mut closed = false;
            while let Some((_, c)) = chars.next() {
                if c == '"' {
                    if chars.peek().map(|p| p.1) == Some('"') {
                        chars.next();
                        field.push('"');
                    } else {
                        closed = true;
                        break;
                    }
                } else {
                    field.push(c);
                }
            }
            if !closed {
                return Err(line[..start].chars().count() + 1);
            }
        }
        let mut end_of_line = true;
        for (_, c) in chars.by_ref() {
            if c == ',' {
                end_of_line = false;
                break;
            }
            field.push(c);
        }
        fields.push(field);
        if end_of_line {
            return Ok(fields);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::split_fields;

    #[test]
    fn quoted_fields_are_one_field() {
        assert_eq!(split_fields("a,b,c").unwrap(), ["a", "b", "c"]);
        assert_eq!(split_fields("\"0.1,0.2\",3").unwrap(), ["0.1,0.2", "3"]);
        assert_eq!(split_fields(" \"x\"\"y\" , 2").unwrap(), ["x\"y ", " 2"]);
        assert_eq!(split_fields("1,,2").unwrap(), ["1", "", "2"]);
        assert_eq!(split_fields("").unwrap(), [""]);
        assert_eq!(split_fields("1,\"2"), Err(3));
    }
}
