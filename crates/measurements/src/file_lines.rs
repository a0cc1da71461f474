//! A record's line as an editor counts it. The CSV layer's own count is the line where
//! it *started looking* for a record: it counts `\n` only, and skips blank lines and the `\n` of a
//! `\r\n` at the start of the next record, so in a file with Windows line ends every row after the
//! first was named one line early (the first data row "line 1"), and a blank line shifted every
//! row after it. Here a record's line is counted from the bytes: the header is line 1 (where no
//! blank line precedes it), every line break counts — `\n`, `\r\n` and a lone `\r`, as the CSV
//! layer itself ends records — inside a quoted field too, and blank lines count.

/// Counts line breaks up to a byte offset, forward only, so that numbering every record of a
/// file reads each byte once.
pub(crate) struct LineCounter<'a> {
    body: &'a [u8],
    /// The offset counted up to.
    byte: usize,
    /// The 1-based line `byte` is on.
    line: u64,
}

impl<'a> LineCounter<'a> {
    /// A counter at the start of `body` (line 1).
    pub fn new(body: &'a [u8]) -> Self {
        Self { body, byte: 0, line: 1 }
    }

    /// Moves to `target` (at most the end), counting the line breaks passed.
    fn advance_to(&mut self, target: usize) {
        let target = target.min(self.body.len());
        while self.byte < target {
            match self.body[self.byte] {
                b'\n' => self.line += 1,
                // `\r\n` is one break, counted at its `\n`; a lone `\r` is one of its own.
                b'\r' if self.body.get(self.byte + 1) != Some(&b'\n') => self.line += 1,
                _ => {}
            }
            self.byte += 1;
        }
    }

    /// The line of the record the CSV layer began reading at byte `start`: the first line at or
    /// after it that is not blank (the layer skips blank lines before a record).
    pub fn record_line(&mut self, start: u64) -> u64 {
        self.advance_to(usize::try_from(start).unwrap_or(usize::MAX));
        while self.byte < self.body.len() && matches!(self.body[self.byte], b'\n' | b'\r') {
            self.advance_to(self.byte + 1);
        }
        self.line
    }
}

/// The line of the record the CSV layer began at `position` (the first line when it gives none).
pub(crate) fn line_of(body: &[u8], position: Option<&csv::Position>) -> u64 {
    position.map_or(1, |p| LineCounter::new(body).record_line(p.byte()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lines of every record of `text` as the reader gives them, header first.
    fn lines(text: &str) -> Vec<u64> {
        let mut reader = csv::ReaderBuilder::new().has_headers(false).flexible(true).from_reader(text.as_bytes());
        let mut counter = LineCounter::new(text.as_bytes());
        let mut record = csv::StringRecord::new();
        let mut out = Vec::new();
        while reader.read_record(&mut record).unwrap() {
            out.push(counter.record_line(record.position().unwrap().byte()));
        }
        out
    }

    /// Where `needle` stands, counted as an editor shows it (1-based line).
    fn editor_line(text: &str, needle: &str) -> u64 {
        let at = text.find(needle).unwrap();
        let before = &text.as_bytes()[..at];
        let breaks = before
            .iter()
            .enumerate()
            .filter(|&(i, &b)| b == b'\n' || (b == b'\r' && before.get(i + 1) != Some(&b'\n')))
            .count();
        breaks as u64 + 1
    }

    #[test]
    fn every_record_is_on_the_line_an_editor_shows() {
        let cases = [
            "h,v\na,1\nb,2\nc,3\n",
            "h,v\r\na,1\r\nb,2\r\nc,3\r\n",
            "h,v\ra,1\rb,2\rc,3",
            "h,v\n\na,1\n\n\nb,2\nc,3",
            "h,v\r\n\r\na,1\r\n\r\nb,2\r\nc,3\r\n",
            "h,v\na,\"one\ntwo\"\nb,\"x\r\ny\r\nz\"\nc,3\n",
            "\n\nh,v\na,1\nb,2\r\n\nc,3",
        ];
        for text in cases {
            let expected: Vec<u64> = ["h,", "a,", "b,", "c,"].iter().map(|n| editor_line(text, n)).collect();
            assert_eq!(lines(text), expected, "{text:?}");
        }
    }

    #[test]
    fn a_file_with_windows_line_ends_is_not_one_line_short() {
        // The CSV layer's own count, for the record: a CRLF file's second row on "line 2".
        let text = "h,v\r\na,1\r\nb,2\r\n";
        let mut reader = csv::ReaderBuilder::new().has_headers(true).from_reader(text.as_bytes());
        let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(records[1].position().unwrap().line(), 2, "the CSV layer's count changed: revisit file_lines");
        assert_eq!(lines(text), [1, 2, 3]);
    }

    /// A file with every quirk: Windows line ends, a blank line, a note over two lines, then a
    /// value that is not a number. Each row and the refusal on the line an editor shows.
    #[test]
    fn the_reader_names_rows_and_refusals_by_their_editor_line() {
        use crate::{ReadOptions, parse_measurements};
        let text = "q1_rad,x_mm,y_mm,z_mm,note\r\n0.1,1,2,3,a\r\n\r\n0.2,1,2,3,\"two\r\nlines\"\r\n0.3,1,2,3,b\r\n";
        let set = parse_measurements(text.as_bytes(), "q.csv", &ReadOptions::default()).unwrap();
        let lines: Vec<u64> = set.rows.iter().map(|r| r.line).collect();
        assert_eq!(lines, [editor_line(text, "0.1"), editor_line(text, "0.2"), editor_line(text, "0.3")]);
        assert_eq!(lines, [2, 4, 6]);
        let bad = format!("{text}0.4,abc,2,3,c\r\n");
        let error = parse_measurements(bad.as_bytes(), "q.csv", &ReadOptions::default()).unwrap_err();
        assert_eq!(error.position(), Some((editor_line(&bad, "0.4,abc"), 2)), "{error}");
        assert!(error.to_string().starts_with("q.csv:7:2: "), "{error}");
        // A row with a field too many, after the same lines: the CSV layer's refusal.
        let bad = format!("{text}0.4,1,2,3,c,d\r\n");
        let error = parse_measurements(bad.as_bytes(), "q.csv", &ReadOptions::default()).unwrap_err();
        assert_eq!(error.position().map(|(line, _)| line), Some(7), "{error}");
        // Blank lines before the header: the header's refusals are on its line.
        let error = parse_measurements("\n\nq1_rad,x_mm,y_mm\n0,1,2\n".as_bytes(), "q.csv", &ReadOptions::default())
            .unwrap_err();
        assert_eq!(error.position(), Some((3, 4)), "{error}");
    }
}
