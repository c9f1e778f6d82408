//! The one Markdown table writer: a header row with each column's alignment, then the rows.

use std::fmt::Write as _;

/// How a column's cells line up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// Text: left.
    Left,
    /// Numbers: right.
    Right,
}

/// A Markdown table being filled row by row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    columns: Vec<(String, Align)>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new<'a>(columns: impl IntoIterator<Item = (&'a str, Align)>) -> Table {
        Table {
            columns: columns
                .into_iter()
                .map(|(c, a)| (c.to_string(), a))
                .collect(),
            rows: Vec::new(),
        }
    }

    /// Adds a row: one cell per column (missing cells are left empty, extra ones dropped).
    pub fn row(&mut self, cells: impl IntoIterator<Item = String>) {
        let mut cells: Vec<String> = cells.into_iter().collect();
        cells.resize(self.columns.len(), String::new());
        self.rows.push(cells);
    }

    /// The table as Markdown, one line per row, ending in a newline.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let names: Vec<&str> = self.columns.iter().map(|(c, _)| c.as_str()).collect();
        let _ = writeln!(s, "| {} |", names.join(" | "));
        let rule: Vec<&str> = self
            .columns
            .iter()
            .map(|(_, a)| match a {
                Align::Left => "---",
                Align::Right => "---:",
            })
            .collect();
        let _ = writeln!(s, "|{}|", rule.join("|"));
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_rule_and_padded_rows() {
        let mut t = Table::new([("name", Align::Left), ("ms", Align::Right)]);
        t.row(["a".to_string(), "1.0".to_string()]);
        t.row(["b".to_string()]);
        assert_eq!(
            t.to_markdown(),
            "| name | ms |\n|---|---:|\n| a | 1.0 |\n| b |  |\n"
        );
    }
}
