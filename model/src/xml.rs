//! A minimal XML outline of URDF text: start tags with their attributes, lines, byte
//! ranges and nesting. Not a validating parser; enough to give urdf-rs's findings a
//! line number and to edit a file in place without touching anything else.

/// A start tag (or empty-element tag) of the source.
#[derive(Debug)]
pub struct Tag {
    pub name: String,
    /// Attributes in source order, entities resolved.
    pub attrs: Vec<(String, String)>,
    /// 1-based line of the `<`.
    pub line: usize,
    /// Bytes of the start tag.
    pub start: std::ops::Range<usize>,
    /// Bytes of the whole element, from `<` of its start tag to `>` of its end tag.
    pub span: std::ops::Range<usize>,
    /// Written as `<name ... />`.
    pub self_closing: bool,
    /// Index of the enclosing tag, `None` for the document element.
    pub parent: Option<usize>,
}

impl Tag {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }
}

/// Where and why the text is not well-formed enough to scan.
#[derive(Debug)]
pub struct SyntaxError {
    pub line: usize,
    pub message: String,
    /// The element that went past [`MAX_DEPTH`], if that is the error: then no
    /// other parser may be given the text.
    pub too_deep: Option<String>,
}

/// Deepest element nesting [`scan`] accepts. A URDF nests five or six levels
/// (`robot/link/visual/geometry/mesh`); the limit keeps the recursive parsers that
/// read the text after the scan far from the end of their stack.
pub const MAX_DEPTH: usize = 256;

/// Scans `text` into its start tags, checking only that tags are closed and nested
/// (at most [`MAX_DEPTH`] deep).
pub fn scan(text: &str) -> Result<Vec<Tag>, SyntaxError> {
    let mut tags: Vec<Tag> = Vec::new();
    // Open elements: (name, tag index).
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut lines = LineCounter::new(text);
    let mut pos = 0;
    while let Some(offset) = text[pos..].find('<') {
        pos += offset;
        let line = lines.line_at(pos);
        let rest = &text[pos..];
        let fail = |message: String| SyntaxError {
            line,
            message,
            too_deep: None,
        };
        let skip_to = |end: &str, what: &str| {
            rest.find(end)
                .map(|k| pos + k + end.len())
                .ok_or_else(|| fail(format!("{what} is never closed")))
        };
        if rest.starts_with("<!--") {
            pos = skip_to("-->", "comment")?;
        } else if rest.starts_with("<![CDATA[") {
            pos = skip_to("]]>", "CDATA section")?;
        } else if rest.starts_with("<?") {
            pos = skip_to("?>", "processing instruction")?;
        } else if rest.starts_with("<!") {
            // A DOCTYPE, possibly with an internal subset in brackets.
            let end = if rest.find('[').is_some_and(|b| rest.find('>').is_some_and(|g| b < g)) {
                "]>"
            } else {
                ">"
            };
            pos = skip_to(end, "declaration")?;
        } else if let Some(after) = rest.strip_prefix("</") {
            let end = after.find('>').ok_or_else(|| fail("end tag is never closed".into()))?;
            let name = after[..end].trim();
            match open.pop() {
                Some((opened, k)) if opened == name => tags[k].span.end = pos + 2 + end + 1,
                Some((opened, k)) => {
                    return Err(fail(format!(
                        "</{name}> closes <{opened}> opened on line {}",
                        tags_line(&tags, k)
                    )))
                }
                None => return Err(fail(format!("</{name}> has no matching start tag"))),
            }
            pos += 2 + end + 1;
        } else {
            let (tag, self_closing, len) = start_tag(rest).map_err(fail)?;
            let name = tag.0;
            let k = tags.len();
            let parent = open.last().map(|&(_, p)| p);
            tags.push(Tag {
                name: name.clone(),
                attrs: tag.1,
                line,
                start: pos..pos + len,
                span: pos..pos + len,
                self_closing,
                parent,
            });
            if !self_closing {
                if open.len() >= MAX_DEPTH {
                    return Err(SyntaxError {
                        line,
                        message: format!(
                            "<{name}> is nested more than {MAX_DEPTH} elements deep; a URDF needs fewer than 10 levels"
                        ),
                        too_deep: Some(name),
                    });
                }
                open.push((name, k));
            }
            pos += len;
        }
    }
    match open.pop() {
        Some((name, k)) => Err(SyntaxError {
            line: tags_line(&tags, k),
            message: format!("<{name}> is never closed"),
            too_deep: None,
        }),
        None if tags.is_empty() => Err(SyntaxError {
            line: 1,
            message: "no XML element found".into(),
            too_deep: None,
        }),
        None => Ok(tags),
    }
}

fn tags_line(tags: &[Tag], k: usize) -> usize {
    tags.get(k).map_or(0, |t| t.line)
}

type StartTag = (String, Vec<(String, String)>);

/// Reads a start tag at the beginning of `s` (which starts with `<`): its name and
/// attributes, whether it is self-closing, and its length in bytes.
fn start_tag(s: &str) -> Result<(StartTag, bool, usize), String> {
    let is_delim = |c: char| c.is_whitespace() || c == '/' || c == '>';
    let body = &s[1..];
    let name_len = body.find(is_delim).unwrap_or(body.len());
    let name = &body[..name_len];
    if name.is_empty() {
        return Err("a `<` that starts no tag (write `&lt;` for a literal `<`)".into());
    }
    let unclosed = || format!("tag <{name}> is never closed");
    let mut attrs = Vec::new();
    let mut i = 1 + name_len;
    loop {
        let rest = &s[i..];
        let trimmed = rest.trim_start();
        i += rest.len() - trimmed.len();
        if trimmed.starts_with("/>") {
            return Ok(((name.to_string(), attrs), true, i + 2));
        }
        if trimmed.starts_with('>') {
            return Ok(((name.to_string(), attrs), false, i + 1));
        }
        if trimmed.is_empty() {
            return Err(unclosed());
        }
        let eq = trimmed.find('=').ok_or_else(unclosed)?;
        let attr = trimmed[..eq].trim();
        if attr.is_empty() || attr.contains(is_delim) {
            return Err(format!("malformed attribute in <{name}>"));
        }
        let value = trimmed[eq + 1..].trim_start();
        let quote = value.chars().next().filter(|&c| c == '"' || c == '\'');
        let quote = quote.ok_or_else(|| format!("attribute `{attr}` of <{name}> needs a quoted value"))?;
        let close = value[1..].find(quote).ok_or_else(unclosed)?;
        attrs.push((attr.to_string(), unescape(&value[1..1 + close])));
        i += trimmed.len() - value.len() + 1 + close + 1;
    }
}

/// Resolves the predefined XML entities and character references, so that names
/// compare equal to what urdf-rs reads.
pub fn unescape(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(k) = rest.find('&') {
        out.push_str(&rest[..k]);
        rest = &rest[k..];
        let resolved = rest.find(';').and_then(|end| {
            let c = match &rest[1..end] {
                "lt" => Some('<'),
                "gt" => Some('>'),
                "amp" => Some('&'),
                "quot" => Some('"'),
                "apos" => Some('\''),
                e => e
                    .strip_prefix("#x")
                    .map(|h| u32::from_str_radix(h, 16))
                    .or_else(|| e.strip_prefix('#').map(str::parse))
                    .and_then(Result::ok)
                    .and_then(char::from_u32),
            }?;
            Some((c, end + 1))
        });
        match resolved {
            Some((c, len)) => {
                out.push(c);
                rest = &rest[len..];
            }
            None => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// 1-based line numbers of byte offsets, for offsets visited in increasing order.
struct LineCounter<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        LineCounter { text, pos: 0, line: 1 }
    }

    fn line_at(&mut self, pos: usize) -> usize {
        self.line += self.text[self.pos..pos].bytes().filter(|&b| b == b'\n').count();
        self.pos = pos;
        self.line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_reports_bad_nesting_with_lines() {
        let e = scan("<robot>\n<link name='a'>\n</robot>").unwrap_err();
        assert_eq!(e.line, 3);
        assert!(
            e.message.contains("</robot> closes <link> opened on line 2"),
            "{}",
            e.message
        );
        let e = scan("<robot>\n<!-- open\n</robot>").unwrap_err();
        assert_eq!((e.line, e.message.as_str()), (2, "comment is never closed"));
        let e = scan("<robot>\n<link name='a\n/></robot>").unwrap_err();
        assert_eq!(e.line, 2);
    }

    #[test]
    fn scan_refuses_deep_nesting_without_recursion() {
        let ok = format!("{}{}", "<a>".repeat(MAX_DEPTH), "</a>".repeat(MAX_DEPTH));
        assert!(scan(&ok).is_ok());
        let deep = format!("<robot>\n{}{}", "<a>".repeat(20_000), "</a>".repeat(20_000));
        let e = scan(&deep).unwrap_err();
        assert_eq!(e.too_deep.as_deref(), Some("a"));
        assert_eq!(e.line, 2);
        assert!(
            e.message.contains("nested more than 256 elements deep"),
            "{}",
            e.message
        );
    }

    #[test]
    fn unescape_entities() {
        assert_eq!(unescape("a&lt;b&gt;&#65;&#x42;&amp;&bogus;"), "a<b>AB&&bogus;");
    }
}
