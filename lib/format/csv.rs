//! The numeric CSV tables `sc-solve` writes beside its results (`<name>.forces.csv`,
//! `<name>.convergence.csv`; columns in `docs/formats.md`), read back by name.
//!
//! ```text
//! increment,load_factor,reaction:base:x,...,active:contact      header: column names
//! 1,1e-2,0e0,...,0                                             one row per line
//! ```
//! Cells are Rust's `{}` / `{:e}` forms of `f64` (`1.9e-26`, `0e0`, `NaN`, `inf`),
//! parsed with `str::parse::<f64>`. An empty cell (a pair without a summary in that
//! increment) is read as NaN: a missing value, not an error. A column name may
//! appear more than once (one node set constrained by two entries gives two
//! identical reaction triples); [`Table::column`] returns the first. There is no
//! quoting: our writers never put a comma or a quote into a name.

use std::path::Path;

/// A CSV file that cannot be read as a numeric table. Every variant names the file,
/// and the ones about a cell its line (1-based, the header is line 1) and column.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: empty file (expected a header line of column names)")]
    Empty { path: String },
    #[error("{path}: has a header but no data rows (did the solve converge any increment?)")]
    NoRows { path: String },
    #[error("{path}: line {line}: {found} cells, but the header has {expected} columns")]
    Ragged { path: String, line: usize, found: usize, expected: usize },
    #[error("{path}: line {line}, column '{column}': cannot read {text:?} as a number")]
    BadNumber { path: String, line: usize, column: String, text: String },
}

/// A numeric table: named columns, one `f64` per cell (NaN where a cell is empty).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The file it was read from, for messages.
    pub path: String,
    /// Column names in file order (duplicates kept).
    pub columns: Vec<String>,
    /// `rows[r][c]`: data row r (file line r + 2), column c.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Read a table from a file.
    pub fn read(path: &Path) -> Result<Self, CsvError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| CsvError::Io { path: shown.clone(), source })?;
        Self::parse(&shown, &text)
    }

    /// Parse a table from CSV text (`path` is for messages). Blank lines are skipped;
    /// `\r\n` line ends and spaces around cells are accepted.
    pub fn parse(path: &str, text: &str) -> Result<Self, CsvError> {
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty());
        let Some((_, header)) = lines.next() else {
            return Err(CsvError::Empty { path: path.to_string() });
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let mut rows = Vec::new();
        for (line, l) in lines {
            let cells: Vec<&str> = l.split(',').map(str::trim).collect();
            if cells.len() != columns.len() {
                return Err(CsvError::Ragged { path: path.to_string(), line, found: cells.len(), expected: columns.len() });
            }
            let row = cells
                .iter()
                .zip(&columns)
                .map(|(cell, column)| match *cell {
                    "" => Ok(f64::NAN),
                    c => c.parse::<f64>().map_err(|_| CsvError::BadNumber { path: path.to_string(), line, column: column.clone(), text: c.to_string() }),
                })
                .collect::<Result<Vec<f64>, CsvError>>()?;
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(CsvError::NoRows { path: path.to_string() });
        }
        Ok(Self { path: path.to_string(), columns, rows })
    }

    /// The index of the first column called `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// The column names without repeats, in file order (for "available columns" messages).
    pub fn distinct_columns(&self) -> Vec<&str> {
        let mut seen: Vec<&str> = Vec::with_capacity(self.columns.len());
        for c in &self.columns {
            if !seen.contains(&c.as_str()) {
                seen.push(c);
            }
        }
        seen
    }

    /// The values of column `c`, one per row.
    pub fn values(&self, c: usize) -> impl Iterator<Item = f64> + '_ {
        self.rows.iter().map(move |r| r[c])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FORCES: &str = "increment,load_factor,reaction:top:y,reaction:top:y,active:contact\n1,1e-2,-2.5e0,9e9,0\n2,2e-2,-5e0,9e9,3\n";

    #[test]
    fn reads_rust_float_forms() {
        let t = Table::parse("f.csv", "a,b,c,d\n0e0,1.9e-26,NaN,-inf\n").unwrap();
        assert_eq!(t.rows[0][0], 0.0);
        assert_eq!(t.rows[0][1], 1.9e-26);
        assert!(t.rows[0][2].is_nan());
        assert_eq!(t.rows[0][3], f64::NEG_INFINITY);
    }

    #[test]
    fn duplicate_column_names_give_the_first() {
        let t = Table::parse("f.csv", FORCES).unwrap();
        let c = t.column("reaction:top:y").unwrap();
        assert_eq!(c, 2);
        assert_eq!(t.values(c).collect::<Vec<_>>(), [-2.5, -5.0]);
        assert_eq!(t.distinct_columns(), ["increment", "load_factor", "reaction:top:y", "active:contact"]);
        assert_eq!(t.column("reaction:top:x"), None);
    }

    #[test]
    fn bad_number_names_file_line_and_column() {
        let e = Table::parse("out/f.csv", &FORCES.replace("-5e0", "-5x0")).unwrap_err().to_string();
        assert!(e.contains("out/f.csv: line 3, column 'reaction:top:y'") && e.contains("\"-5x0\""), "{e}");
        // a blank line does not shift the count: lines are the file's lines
        let e = Table::parse("f.csv", &FORCES.replace("\n2,", "\n\n2,").replace("-5e0", "?")).unwrap_err().to_string();
        assert!(e.contains("line 4"), "{e}");
    }

    #[test]
    fn ragged_row_names_the_line() {
        let e = Table::parse("f.csv", &FORCES.replace(",0\n", "\n")).unwrap_err().to_string();
        assert!(e.contains("f.csv: line 2: 4 cells") && e.contains("5 columns"), "{e}");
    }

    #[test]
    fn empty_cell_is_a_missing_value() {
        let t = Table::parse("f.csv", "a,b\n1,\n").unwrap();
        assert!(t.rows[0][1].is_nan());
    }

    #[test]
    fn empty_file_and_header_only_are_errors() {
        assert!(matches!(Table::parse("f.csv", ""), Err(CsvError::Empty { .. })));
        assert!(matches!(Table::parse("f.csv", "\n\n"), Err(CsvError::Empty { .. })));
        let e = Table::parse("f.csv", "increment,load_factor\n").unwrap_err();
        assert!(matches!(e, CsvError::NoRows { .. }), "{e}");
        assert!(e.to_string().contains("f.csv"));
    }

    #[test]
    fn crlf_and_blank_lines() {
        let t = Table::parse("f.csv", "a,b\r\n\r\n1,2\r\n3,4\r\n\r\n").unwrap();
        assert_eq!(t.rows, vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
    }
}
