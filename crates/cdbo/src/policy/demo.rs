//! A demonstration lap as CSV: the (x, a) pairs w₀ is fitted to (paper eq. 9).
//!
//! Rows `x,a`, or with a header, the columns named `x` and `a` (or `pedal`) of a wider table
//! such as `cdbo lap --trace`. Blank lines and `#` comments are skipped.

use crate::error::{Error, Result};

/// Parses a demonstration; `file` names the text in errors, each with its line.
pub fn parse(text: &str, file: &str) -> Result<Vec<(f64, f64)>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .peekable();
    let (mut xc, mut ac) = (0, 1);
    if let Some(&(i, first)) = lines.peek()
        && first
            .trim_start()
            .chars()
            .next()
            .is_some_and(char::is_alphabetic)
    {
        let header: Vec<&str> = first.split(',').map(str::trim).collect();
        let column = |names: &[&str], what: &str| {
            header
                .iter()
                .position(|h| names.contains(h))
                .ok_or_else(|| Error::Parse {
                    file: file.to_owned(),
                    line: Some(i as u32 + 1),
                    element: "header".into(),
                    message: format!("no {what} column"),
                })
        };
        xc = column(&["x"], "x")?;
        ac = column(&["a", "pedal"], "a (or pedal)")?;
        lines.next();
    }
    let mut pairs = Vec::new();
    for (i, line) in lines {
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let get = |c: usize| -> Result<f64> {
            cols.get(c)
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| Error::Parse {
                    file: file.to_owned(),
                    line: Some(i as u32 + 1),
                    element: format!("column {}", c + 1),
                    message: format!("{:?} is not a finite number", cols.get(c).unwrap_or(&"")),
                })
        };
        pairs.push((get(xc)?, get(ac)?));
    }
    if pairs.is_empty() {
        return Err(Error::parse(file, "rows", "the demonstration is empty"));
    }
    Ok(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_named_columns_and_names_the_line_of_a_bad_value() {
        let text = "# a trace\nt,x,v,pedal\n0,0.0,1,0.5\n\n0.02,0.1,2,0.7\n";
        assert_eq!(parse(text, "d.csv").unwrap(), vec![(0.0, 0.5), (0.1, 0.7)]);
        let e = parse(&text.replace("0.7", "NaN"), "d.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("d.csv:5: column 4") && e.contains("NaN"),
            "{e}"
        );
        let e = parse("t,v\n1,2\n", "d.csv").unwrap_err().to_string();
        assert!(e.starts_with("d.csv:1: header: no x column"), "{e}");
        assert!(parse("# nothing\n", "d.csv").is_err());
    }
}
