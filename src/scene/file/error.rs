//! What a user gets for a mistake in a scene file or a mesh: the file, the line and column, what
//! was wrong and what would be right. Positions come from byte offsets into the source.

use std::fmt;

use crate::text::printable;

/// A mistake in a scene file or in a mesh it names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneFileError {
    /// The file the mistake is in, as the user named it (control characters removed).
    pub file: String,
    /// 1-based line; 0 when the mistake is about the file as a whole (it cannot be read).
    pub line: usize,
    /// 1-based column in characters; 0 with `line` 0.
    pub column: usize,
    /// What was wrong and what would be right (control characters removed).
    pub message: String,
    /// The line in question, control characters removed, cut to about [`EXCERPT_CHARS`]
    /// characters around the column; empty when there is none to show.
    pub excerpt: String,
    /// The column within `excerpt` (1-based), for the caret under it.
    pub excerpt_column: usize,
}

/// Most characters of a line shown under an error.
pub const EXCERPT_CHARS: usize = 100;

impl SceneFileError {
    /// An error at byte `offset` of `source` (clamped to its length).
    pub fn at(file: &str, source: &str, offset: usize, message: impl Into<String>) -> Self {
        let (line, column) = line_column(source, offset);
        SceneFileError::at_line(file, source, line, column, message)
    }

    /// An error at a 1-based `line` and `column` (in characters) of `text`.
    pub fn at_line(
        file: &str,
        text: &str,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        let whole = text.split('\n').nth(line.saturating_sub(1)).unwrap_or("");
        SceneFileError::on_line(file, whole, line, column, message)
    }

    /// An error at 1-based `column` (in characters) of `whole`, which is line `line` of the
    /// file: for callers that hold the file as bytes and convert only the line shown.
    pub fn on_line(
        file: &str,
        whole: &str,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        // Tabs become spaces so that the caret stays under the column.
        let chars: Vec<char> = whole
            .chars()
            .map(|c| if c == '\t' { ' ' } else { c })
            .collect();
        let start = column.saturating_sub(EXCERPT_CHARS / 2).min(chars.len());
        let end = (start + EXCERPT_CHARS).min(chars.len());
        let shown: String = chars[start..end].iter().collect();
        SceneFileError {
            file: printable(file),
            line,
            column,
            message: printable(&message.into()),
            excerpt: printable(shown.trim_end()),
            excerpt_column: column - start,
        }
    }

    /// An error about a whole file (no position), such as one that cannot be read.
    pub fn whole_file(file: &str, message: impl Into<String>) -> Self {
        SceneFileError {
            file: printable(file),
            line: 0,
            column: 0,
            message: printable(&message.into()),
            excerpt: String::new(),
            excerpt_column: 0,
        }
    }
}

impl fmt::Display for SceneFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            return write!(f, "{}: {}", self.file, self.message);
        }
        write!(
            f,
            "{}:{}:{}: {}",
            self.file, self.line, self.column, self.message
        )?;
        if !self.excerpt.is_empty() {
            let gutter = self.line.to_string().len();
            write!(
                f,
                "\n {} | {}\n {:gutter$} | {:>col$}",
                self.line,
                self.excerpt,
                "",
                "^",
                col = self.excerpt_column.max(1)
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneFileError {}

/// The 1-based line and column (in characters) of byte `offset` in `source`.
pub fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

/// The known name closest to `word`, if it is close enough to be a likely typo: at most 2 edits
/// (insertions, deletions, substitutions, swaps of two neighbours: `strsim`'s optimal string
/// alignment distance), and fewer than half of the word's characters.
pub fn suggest<'a>(word: &str, known: &[&'a str]) -> Option<&'a str> {
    // Typos longer than this are not worth comparing (and keep the quadratic distance cheap).
    const LONGEST: usize = 64;
    if word.chars().count() > LONGEST {
        return None;
    }
    let limit = 2.min(word.chars().count().div_ceil(2));
    known
        .iter()
        .map(|k| (strsim::osa_distance(&word.to_lowercase(), k), *k))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, k)| k)
}

/// " did you mean `x`?" when `word` is close to one of `known`, else "".
pub fn did_you_mean(word: &str, known: &[&str]) -> String {
    match suggest(word, known) {
        Some(k) => format!("; did you mean `{k}`?"),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_and_count_characters() {
        let s = "a = 1\nbé = 2\n";
        assert_eq!(line_column(s, 0), (1, 1));
        assert_eq!(line_column(s, 6), (2, 1));
        assert_eq!(line_column(s, s.find('=').unwrap()), (1, 3));
        let second = s.rfind('=').unwrap();
        assert_eq!(line_column(s, second), (2, 4));
        assert_eq!(line_column(s, 10_000), (3, 1));
    }

    #[test]
    fn the_line_is_shown_with_a_caret_under_the_column() {
        let e = SceneFileError::at("f.toml", "a = 1\n\tcolr = 2\n", 7, "unknown key");
        assert_eq!(
            e.to_string(),
            "f.toml:2:2: unknown key\n 2 |  colr = 2\n   |  ^"
        );
        // A long line is cut around the column, and the caret follows.
        let long = format!("x = [{}9]", "1, ".repeat(200));
        let e = SceneFileError::at("f.toml", &long, long.len() - 2, "here");
        let caret = e.to_string().lines().last().unwrap().len();
        let shown = e.to_string().lines().nth(1).unwrap().to_string();
        assert_eq!(shown.as_bytes()[caret - 1], b'9', "{e}");
        assert!(e.excerpt.chars().count() <= EXCERPT_CHARS);
    }

    #[test]
    fn close_typos_get_a_suggestion_and_far_ones_none() {
        let known = ["colour", "mirror"];
        assert_eq!(suggest("color", &known), Some("colour"));
        assert_eq!(suggest("mirorr", &known), Some("mirror"));
        assert_eq!(suggest("Colour", &known), Some("colour"));
        assert_eq!(suggest("size", &known), None);
        assert_eq!(suggest("m", &known), None);
        // A swap of two neighbours is one edit.
        assert_eq!(suggest("mirorr", &["mirror", "morrir"]), Some("mirror"));
        assert_eq!(suggest("clouor", &known), Some("colour"));
    }
}
