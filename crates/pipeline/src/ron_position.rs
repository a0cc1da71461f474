//! Positions of fields in RON text, so that a value refused after parsing (an axis that is not a
//! unit vector, say) is reported at its line and column like a syntax error.

/// The RON options every file of ours is read with: `Some(..)` may be left out of optional fields.
pub(crate) fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

/// 1-based line and column of the `index`-th (0-based) occurrence of `field:` in `text` outside
/// comments and strings; (1, 1) when there are not that many.
pub(crate) fn field_position(text: &str, field: &str, index: usize) -> (usize, usize) {
    let bytes = text.as_bytes();
    let mut seen = 0;
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
            if seen == index {
                return (line, column);
            }
            seen += 1;
        }
        let c = rest.chars().next().unwrap_or(' ');
        (line, column) = if c == '\n' { (line + 1, 1) } else { (line, column + 1) };
        i += c.len_utf8();
    }
    (1, 1)
}

#[cfg(test)]
mod tests {
    use super::field_position;

    #[test]
    fn field_positions_skip_comments_strings_and_longer_names() {
        let text = "// axis: no\n(name: \"axis: no\", my_axis: 1,\n  axis: (1, 0, 0), axis : 2)";
        assert_eq!(field_position(text, "axis", 0), (3, 3));
        assert_eq!(field_position(text, "axis", 1), (3, 20));
        assert_eq!(field_position(text, "axis", 2), (1, 1));
    }
}
