//! The outline of an XML document: its elements with their attributes, byte spans and 1-based
//! line and column: the one reading of a URDF's XML (`urdf_model.rs` reads the links and joints
//! from it). It lets a refusal name the line and column of the element at fault, and lets the URDF
//! export edit a file in place (so that what it does
//! not understand, `<transmission>`, `<gazebo>`, `<ros2_control>`, comments, stays as it was).

/// A 1-based line and column.
pub type Position = (usize, usize);

/// One element.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Tag name, with any prefix (`xacro:macro`).
    pub name: String,
    /// Attributes in document order, entities decoded.
    pub attributes: Vec<(String, String)>,
    /// Where `<` of the start tag is.
    pub position: Position,
    /// Byte range of the whole element, start tag to end tag.
    pub span: (usize, usize),
    /// Child elements in order.
    pub children: Vec<Element>,
}

impl Element {
    /// The value of attribute `name`.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    /// The first child named `name`.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
}

/// Deepest nesting of elements accepted. A URDF is four levels deep (`robot`, `link`, `visual`,
/// `geometry`, `mesh`), xacro-expanded files and `<gazebo>` blocks a few more; the outline and
/// its users recurse once per level, so a hostile file nested 200,000 deep would overflow the
/// stack (the process aborts, no message) where it is now refused at the element too deep.
pub const MAX_DEPTH: usize = 256;

/// A syntax error: where, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    /// Where the document stops being XML.
    pub position: Position,
    /// What is wrong there.
    pub message: String,
}

struct Cursor<'a> {
    text: &'a str,
    at: usize,
    line: usize,
    column: usize,
}

impl Cursor<'_> {
    fn rest(&self) -> &str {
        &self.text[self.at..]
    }

    fn position(&self) -> Position {
        (self.line, self.column)
    }

    fn advance(&mut self, bytes: usize) {
        let end = (self.at + bytes).min(self.text.len());
        for c in self.text[self.at..end].chars() {
            (self.line, self.column) = if c == '\n' { (self.line + 1, 1) } else { (self.line, self.column + 1) };
        }
        self.at = end;
    }

    fn error(&self, message: impl Into<String>) -> SyntaxError {
        SyntaxError { position: self.position(), message: message.into() }
    }

    /// Skips past `end`, or fails with `what` at the start.
    fn skip_past(&mut self, end: &str, what: &str) -> Result<(), SyntaxError> {
        let start = self.error(format!("{what} is not closed with '{end}'"));
        match self.rest().find(end) {
            Some(i) => {
                self.advance(i + end.len());
                Ok(())
            }
            None => Err(start),
        }
    }

    fn skip_space(&mut self) {
        let n = self.rest().len() - self.rest().trim_start().len();
        self.advance(n);
    }

    fn name(&mut self) -> String {
        let n = self.rest().find(|c: char| c.is_whitespace() || matches!(c, '/' | '>' | '=')).unwrap_or(0);
        let name = self.rest()[..n].to_owned();
        self.advance(n);
        name
    }
}

/// An attribute value with its references decoded: the five predefined entities and character
/// references (`&#65;`, `&#x41;`). Any other `&` is refused, as an XML parser refuses it.
fn decode(value: &str) -> Result<String, String> {
    let mut decoded = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(i) = rest.find('&') {
        decoded.push_str(&rest[..i]);
        rest = &rest[i..];
        let Some(end) = rest.find(';') else {
            return Err("'&' that starts no entity (write '&amp;')".into());
        };
        let name = &rest[1..end];
        let character = match name {
            "quot" => Some('"'),
            "apos" => Some('\''),
            "lt" => Some('<'),
            "gt" => Some('>'),
            "amp" => Some('&'),
            _ => match name.strip_prefix("#x").or_else(|| name.strip_prefix("#X")) {
                Some(hex) => u32::from_str_radix(hex, 16).ok().and_then(char::from_u32),
                None => name.strip_prefix('#').and_then(|d| d.parse::<u32>().ok()).and_then(char::from_u32),
            },
        };
        let Some(character) = character else {
            return Err(format!("invalid entity '&{name};'"));
        };
        decoded.push(character);
        rest = &rest[end + 1..];
    }
    decoded.push_str(rest);
    Ok(decoded)
}

/// A start tag: name, attributes, and whether it closes itself (`<a/>`).
struct StartTag {
    name: String,
    attributes: Vec<(String, String)>,
    closed: bool,
}

/// Reads a start tag after its `<`.
fn start_tag(cursor: &mut Cursor<'_>, position: Position) -> Result<StartTag, SyntaxError> {
    let name = cursor.name();
    if name.is_empty() {
        return Err(SyntaxError { position, message: "'<' is not followed by an element name".into() });
    }
    let mut attributes = Vec::new();
    // Names seen, so that an element with 100,000 attributes is read in linear time.
    let mut seen = std::collections::HashSet::new();
    loop {
        cursor.skip_space();
        let rest = cursor.rest();
        if rest.starts_with("/>") {
            cursor.advance(2);
            return Ok(StartTag { name, attributes, closed: true });
        }
        if rest.starts_with('>') {
            cursor.advance(1);
            return Ok(StartTag { name, attributes, closed: false });
        }
        if rest.is_empty() || rest.starts_with('<') {
            return Err(SyntaxError { position, message: format!("start tag <{name}> is not closed with '>'") });
        }
        let attribute_at = cursor.error("");
        let attribute = cursor.name();
        cursor.skip_space();
        if attribute.is_empty() || !cursor.rest().starts_with('=') {
            return Err(SyntaxError {
                position: attribute_at.position,
                message: format!("attribute '{attribute}' of <{name}> has no '=' and value"),
            });
        }
        cursor.advance(1);
        cursor.skip_space();
        let quote = cursor.rest().chars().next().filter(|c| matches!(c, '"' | '\''));
        let Some(quote) = quote else {
            return Err(cursor.error(format!("the value of attribute '{attribute}' is not quoted")));
        };
        cursor.advance(1);
        let Some(end) = cursor.rest().find(quote) else {
            return Err(SyntaxError {
                position: attribute_at.position,
                message: format!("the value of attribute '{attribute}' is not closed"),
            });
        };
        let value = decode(&cursor.rest()[..end]).map_err(|why| SyntaxError {
            position: attribute_at.position,
            message: format!("attribute '{attribute}' of <{name}>: {why}"),
        })?;
        cursor.advance(end + 1);
        if !seen.insert(attribute.clone()) {
            return Err(SyntaxError {
                position: attribute_at.position,
                message: format!("attribute '{attribute}' appears twice"),
            });
        }
        attributes.push((attribute, value));
    }
}

/// The document's root element, or the first syntax error.
pub fn outline(text: &str) -> Result<Element, SyntaxError> {
    let mut cursor = Cursor { text, at: 0, line: 1, column: 1 };
    let mut tree = Tree::default();
    while let Some(i) = cursor.rest().find('<') {
        cursor.advance(i);
        let rest = cursor.rest();
        if rest.starts_with("<!--") {
            cursor.skip_past("-->", "a comment")?;
        } else if rest.starts_with("<![CDATA[") {
            cursor.skip_past("]]>", "a CDATA section")?;
        } else if rest.starts_with("<?") {
            cursor.skip_past("?>", "a processing instruction")?;
        } else if rest.starts_with("<!") {
            cursor.skip_past(">", "a declaration")?;
        } else if rest.starts_with("</") {
            tree.end_tag(&mut cursor)?;
        } else {
            tree.start_tag(&mut cursor)?;
        }
    }
    tree.root()
}

/// The elements read so far: those still open, innermost last, and the root once it is closed.
#[derive(Default)]
struct Tree {
    open: Vec<Element>,
    root: Option<Element>,
}

impl Tree {
    /// Puts a closed element into its parent, or makes it the root.
    fn place_closed(&mut self, element: Element) {
        match self.open.last_mut() {
            Some(parent) => parent.children.push(element),
            None => self.root = Some(element),
        }
    }

    /// Reads the end tag at the cursor (at its `</`), which closes the innermost open element.
    fn end_tag(&mut self, cursor: &mut Cursor<'_>) -> Result<(), SyntaxError> {
        let position = cursor.position();
        cursor.advance(2);
        let name = cursor.name();
        cursor.skip_space();
        if !cursor.rest().starts_with('>') {
            return Err(SyntaxError { position, message: format!("end tag </{name}> is not closed with '>'") });
        }
        cursor.advance(1);
        let Some(mut element) = self.open.pop() else {
            return Err(SyntaxError { position, message: format!("end tag </{name}> has no start tag") });
        };
        if element.name != name {
            return Err(SyntaxError {
                position,
                message: format!(
                    "end tag </{name}> does not match <{}> opened at line {}, column {}",
                    element.name, element.position.0, element.position.1
                ),
            });
        }
        element.span.1 = cursor.at;
        self.place_closed(element);
        Ok(())
    }

    /// Reads the start tag at the cursor (at its `<`): one root, nested at most [`MAX_DEPTH`] deep.
    fn start_tag(&mut self, cursor: &mut Cursor<'_>) -> Result<(), SyntaxError> {
        let (position, start) = (cursor.position(), cursor.at);
        cursor.advance(1);
        let StartTag { name, attributes, closed } = start_tag(cursor, position)?;
        if self.root.is_some() && self.open.is_empty() {
            return Err(SyntaxError { position, message: format!("<{name}> follows the root element") });
        }
        if self.open.len() >= MAX_DEPTH {
            return Err(SyntaxError {
                position,
                message: format!(
                    "<{name}> is nested {} elements deep, at most {MAX_DEPTH} are read",
                    self.open.len() + 1
                ),
            });
        }
        let element = Element { name, attributes, position, span: (start, cursor.at), children: Vec::new() };
        if closed {
            self.place_closed(element);
        } else {
            self.open.push(element);
        }
        Ok(())
    }

    /// The root, once the text is read: refused while an element is still open or without one.
    fn root(mut self) -> Result<Element, SyntaxError> {
        if let Some(unclosed) = self.open.pop() {
            return Err(SyntaxError {
                position: unclosed.position,
                message: format!("<{}> is never closed", unclosed.name),
            });
        }
        self.root.ok_or_else(|| SyntaxError { position: (1, 1), message: "no root element".into() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_outline_has_positions_spans_and_decoded_attributes() {
        let text = "<?xml version=\"1.0\"?>\n<!-- a <fake> one -->\n<robot name='r&amp;&#x64;'>\n  <link name=\"a\"/>\n  <joint name=\"j\">\n    <parent link=\"a\" />\n  </joint>\n</robot>\n";
        let root = outline(text).unwrap();
        assert_eq!((root.name.as_str(), root.attribute("name"), root.position), ("robot", Some("r&d"), (3, 1)));
        let joint = &root.children[1];
        assert_eq!((joint.name.as_str(), joint.position), ("joint", (5, 3)));
        assert_eq!(joint.child("parent").and_then(|p| p.attribute("link")), Some("a"));
        assert!(text[joint.span.0..joint.span.1].starts_with("<joint") && text[..joint.span.1].ends_with("</joint>"));
    }

    #[test]
    fn syntax_errors_are_found_at_their_line_and_column() {
        // 200,000 levels overflowed the stack (found by `cargo xtask fuzz`); MAX_DEPTH + 1 is refused.
        let deep = "<a>".repeat(200_000) + &"</a>".repeat(200_000);
        for (text, position, words) in [
            ("<robot>\n  <link name=\"a\">\n</robot>", (3, 1), "does not match <link> opened at line 2, column 3"),
            ("<robot>\n  <link name=\"a\"/>", (1, 1), "<robot> is never closed"),
            ("<robot>\n  <link name=a/>\n</robot>", (2, 14), "not quoted"),
            ("<robot>\n  <link name=\"a/>\n</robot>", (2, 9), "not closed"),
            ("<robot>\n <!-- open\n</robot>", (2, 2), "comment is not closed"),
            ("<robot/>\n<robot/>", (2, 1), "follows the root element"),
            ("<robot>\n  <link name=\"a\" name=\"b\"/>\n</robot>", (2, 18), "appears twice"),
            ("<robot>\n  <link name=\"t&foo;ip\"/>\n</robot>", (2, 9), "invalid entity '&foo;'"),
            ("<robot>\n  <link name=\"a & b\"/>\n</robot>", (2, 9), "'&' that starts no entity"),
            (deep.as_str(), (1, 1 + 3 * MAX_DEPTH), "nested 257 elements deep"),
        ] {
            let error = outline(text).unwrap_err();
            assert_eq!(error.position, position, "{text}: {}", error.message);
            assert!(error.message.contains(words), "{}", error.message);
        }
    }
}
