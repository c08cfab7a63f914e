//! `sc-plot`'s short form of a series on the command line: `FILE:COLUMN[:SCALE]`.
//!
//! Column names hold colons themselves (`reaction:indenter_top:y`), so the file is
//! everything up to the first `.csv:` (or, for a file not named `*.csv`, up to the
//! first colon), the column the rest, and a last `:`-field that reads as a number
//! is the scale: `out/a.forces.csv:reaction:indenter_top:y:-1`.

use super::SeriesSpec;

/// Parse `FILE:COLUMN[:SCALE]` into a series (no label, no divisor).
pub fn parse_series(arg: &str) -> Result<SeriesSpec, String> {
    let usage = || format!("{arg:?}: expected FILE:COLUMN[:SCALE], e.g. out/a.forces.csv:reaction:top:y:-1");
    let (file, rest) = match arg.find(".csv:") {
        Some(i) => (&arg[..i + 4], &arg[i + 5..]),
        None => arg.split_once(':').ok_or_else(usage)?,
    };
    let (column, scale) = match rest.rsplit_once(':') {
        Some((c, s)) => match s.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => (c, v),
            Ok(v) => return Err(format!("{arg:?}: the scale must be a finite number, found {v}")),
            Err(_) => (rest, 1.0),
        },
        None => (rest, 1.0),
    };
    if file.is_empty() || column.is_empty() {
        return Err(usage());
    }
    Ok(SeriesSpec { input: file.into(), column: column.to_string(), scale, divide_by: None, label: None })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_column_and_scale() {
        let s = parse_series("out/a.forces.csv:reaction:indenter_top:y:-1").unwrap();
        assert_eq!(s.input.to_str(), Some("out/a.forces.csv"));
        assert_eq!(s.column, "reaction:indenter_top:y");
        assert_eq!(s.scale, -1.0);
        let s = parse_series("a.forces.csv:active:contact").unwrap();
        assert_eq!((s.column.as_str(), s.scale), ("active:contact", 1.0));
        let s = parse_series("log.txt:load_factor:2.5e-1").unwrap();
        assert_eq!((s.input.to_str(), s.column.as_str(), s.scale), (Some("log.txt"), "load_factor", 0.25));
    }

    #[test]
    fn malformed_is_an_error_with_the_form() {
        for bad in ["a.csv", "a.csv:", ":x", "a.csv::2", "a.csv:x:inf"] {
            let e = parse_series(bad).unwrap_err();
            assert!(e.contains(bad), "{e}");
        }
    }
}
