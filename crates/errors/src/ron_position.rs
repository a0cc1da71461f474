//! Positions of fields in RON text, so that a value refused after parsing (an axis that is not a
//! unit vector, say) is reported at its line and column like a syntax error.

/// The text of a RON file; bytes that are not UTF-8 are refused at their line and column (the
/// standard library's message names neither).
pub fn read_text(path: &std::path::Path) -> Result<String, crate::Error> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| crate::Error::io(file.clone(), source))?;
    text_of(bytes, &file)
}

/// `bytes` as text, or the position of the first byte that is not UTF-8.
pub fn text_of(bytes: Vec<u8>, file: &str) -> Result<String, crate::Error> {
    String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let valid = std::str::from_utf8(valid).unwrap_or_default();
        let line = valid.matches('\n').count() as u64 + 1;
        let column = valid.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        crate::Error::at_line(file, line, column, crate::CommonKind::InvalidUtf8)
    })
}

/// The RON options every file of ours is read with: `Some(..)` may be left out of optional fields.
pub fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

/// 1-based line and column of the `index`-th (0-based) occurrence of `field:` in `text` outside
/// comments and strings; (1, 1) when there are not that many.
pub fn field_position(text: &str, field: &str, index: usize) -> (usize, usize) {
    occurrences(text, field).get(index).map_or((1, 1), |&(_, line, column)| (line, column))
}

/// The position of the `index`-th occurrence of `field:` after the first `section:` (a field of a
/// nested struct, say the third `joint_index` in `periodic`); the section's own position when there
/// are not that many (the field left out, its default used), and (1, 1) without the section.
pub fn field_position_in(text: &str, section: &str, field: &str, index: usize) -> (usize, usize) {
    let Some(&(start, line, column)) = occurrences(text, section).first() else { return (1, 1) };
    occurrences(text, field)
        .into_iter()
        .filter(|&(offset, _, _)| offset > start)
        .nth(index)
        .map_or((line, column), |(_, line, column)| (line, column))
}

/// Byte offset, 1-based line and column of every occurrence of `field:` in `text` outside comments
/// and strings, in order.
fn occurrences(text: &str, field: &str) -> Vec<(usize, usize, usize)> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let (mut line, mut column) = (1, 1);
    let mut i = 0;
    while i < bytes.len() {
        let rest = &text[i..];
        if rest.starts_with("//") {
            match rest.find('\n') {
                Some(end) => i += end,
                None => break,
            }
            continue;
        }
        if rest.starts_with("/*") {
            let end = rest.find("*/").map_or(rest.len(), |e| e + 2);
            for c in rest[..end].chars() {
                (line, column) = if c == '\n' { (line + 1, 1) } else { (line, column + 1) };
            }
            i += end;
            continue;
        }
        if bytes[i] == b'"' {
            let mut j = i + 1;
            while j < bytes.len() && bytes[j] != b'"' {
                j += if bytes[j] == b'\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(bytes.len());
            column += text[i..end].chars().count();
            i = end;
            continue;
        }
        let boundary = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if boundary && rest.starts_with(field) && rest[field.len()..].trim_start().starts_with(':') {
            found.push((i, line, column));
        }
        let c = rest.chars().next().unwrap_or(' ');
        (line, column) = if c == '\n' { (line + 1, 1) } else { (line, column + 1) };
        i += c.len_utf8();
    }
    found
}

#[cfg(test)]
mod tests {
    use super::{field_position, field_position_in, text_of};

    #[test]
    fn bytes_that_are_not_utf8_are_placed_at_their_line_and_column() {
        let error = text_of(b"(a: 1,\n  b: \"\xff\")".to_vec(), "r.ron").unwrap_err();
        assert_eq!(error.to_string(), "r.ron:2:7: the text is not UTF-8");
    }

    #[test]
    fn field_positions_skip_comments_strings_and_longer_names() {
        let text = "// axis: no\n(name: \"axis: no\", my_axis: 1,\n  axis: (1, 0, 0), axis : 2)";
        assert_eq!(field_position(text, "axis", 0), (3, 3));
        assert_eq!(field_position(text, "axis", 1), (3, 20));
        assert_eq!(field_position(text, "axis", 2), (1, 1));
    }

    #[test]
    fn a_field_is_found_within_its_section_or_the_section_stands_for_it() {
        let text = "(backlash: (joints: [(joint_index: 1)]),\n periodic: (harmonics: [\n  (joint_index: 0),\n  (joint_index: 9)]))";
        assert_eq!(field_position_in(text, "periodic", "joint_index", 1), (4, 4));
        assert_eq!(field_position_in(text, "backlash", "joint_index", 0), (1, 23));
        assert_eq!(field_position_in(text, "periodic", "order", 0), (2, 2));
        assert_eq!(field_position_in(text, "thermal", "order", 0), (1, 1));
    }
}
