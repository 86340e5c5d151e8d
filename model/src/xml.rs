//! A minimal XML outline of URDF and MJCF text: start tags with their attributes,
//! lines, byte ranges and nesting. Not a validating parser, but strict where a
//! parser reading the text after it could go wrong: the nesting limit, one document
//! element, entity references, characters XML forbids, names that no code can
//! carry. Enough to give urdf-rs's findings a line number and to edit a file in
//! place without touching anything else. Every loop is linear in the text.

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

/// Longest `name` (or MJCF `model`) attribute [`scan`] accepts, in characters. Real
/// names are a few dozen characters; names become Rust identifiers, documentation
/// and table columns.
pub const MAX_NAME_CHARS: usize = 1024;

/// The attributes that name an element, checked by [`scan`] ([`name_problem`]).
const NAME_ATTRIBUTES: [&str; 2] = ["name", "model"];

/// Scans `text` into its start tags, checking that tags are closed and nested (at
/// most [`MAX_DEPTH`] deep) in exactly one document element, that the text holds
/// only characters XML allows, that every `&` starts a predefined entity or a
/// character reference, and that names are printable and at most
/// [`MAX_NAME_CHARS`] long. A leading byte order mark is skipped; `\r\n`, `\r` and
/// `\n` each end a line.
pub fn scan(text: &str) -> Result<Vec<Tag>, SyntaxError> {
    let mut lines = LineCounter::new(text);
    let fail_at = |lines: &mut LineCounter, at: usize, message: String| SyntaxError {
        line: lines.line_at(at),
        message,
        too_deep: None,
    };
    if let Some((at, c)) = forbidden_char(text) {
        return Err(SyntaxError {
            line: line_of(text, at),
            message: format!("{} is not allowed in XML text; remove it", describe_char(c)),
            too_deep: None,
        });
    }
    let mut tags: Vec<Tag> = Vec::new();
    // Open elements: (name, tag index).
    let mut open: Vec<(String, usize)> = Vec::new();
    // The document element once it is closed: (name, line).
    let mut closed_root: Option<(String, usize)> = None;
    let mut doctype_seen = false;
    let mut pos = if text.starts_with('\u{feff}') {
        '\u{feff}'.len_utf8()
    } else {
        0
    };
    loop {
        let next = text[pos..].find('<').map_or(text.len(), |k| pos + k);
        // Character data up to the next markup.
        let data = &text[pos..next];
        if open.is_empty() {
            if let Some(k) = data.find(|c: char| !is_xml_space(c)) {
                let where_ = match &closed_root {
                    Some((name, _)) => format!("after the document element <{}>", shorten(name)),
                    None => "before the document element".to_string(),
                };
                return Err(fail_at(
                    &mut lines,
                    pos + k,
                    format!("text {where_}; an XML document holds its text inside one element"),
                ));
            }
        } else if let Err((k, message)) = check_references(data) {
            return Err(fail_at(&mut lines, pos + k, format!("{message} in text")));
        }
        if next == text.len() {
            break;
        }
        pos = next;
        let line = lines.line_at(pos);
        let rest = &text[pos..];
        let fail = |message: String| SyntaxError {
            line,
            message,
            too_deep: None,
        };
        // The end of what `open` opens: `close` (searched for after `open`), the
        // offset of its content and the content.
        let skip_to = |open: &str, close: &str, what: &str| {
            let content = &rest[open.len()..];
            content
                .find(close)
                .map(|k| (pos + open.len() + k + close.len(), pos + open.len(), &content[..k]))
                .ok_or_else(|| fail(format!("{what} is never closed (it needs `{close}`)")))
        };
        if rest.starts_with("<!--") {
            // As XML has it, and as urdf-rs's reader reads it: no `--` inside.
            let (end, at, content) = skip_to("<!--", "--", "comment")?;
            if !text[end..].starts_with('>') {
                return Err(fail_at(
                    &mut lines,
                    at + content.len(),
                    "`--` inside a comment, which ends at the first `--` (with `-->`)".into(),
                ));
            }
            pos = end + 1;
        } else if rest.starts_with("<![CDATA[") {
            if open.is_empty() {
                return Err(fail("a CDATA section outside the document element".into()));
            }
            pos = skip_to("<![CDATA[", "]]>", "CDATA section")?.0;
        } else if rest.starts_with("<?") {
            let (end, at, content) = skip_to("<?", "?>", "processing instruction")?;
            // urdf-rs's reader ends it at the first `>` after any `?`, and would read
            // what follows as elements that no scan has counted.
            if let Some(k) = content.find('>') {
                return Err(fail_at(
                    &mut lines,
                    at + k,
                    "a `>` inside a processing instruction `<?...?>`; remove it".into(),
                ));
            }
            pos = end;
        } else if rest.starts_with("<!DOCTYPE") {
            if doctype_seen || !tags.is_empty() {
                return Err(fail(
                    "a <!DOCTYPE> after the first one or after the document element; a document has at most one, \
                     before its element"
                        .into(),
                ));
            }
            doctype_seen = true;
            let len = doctype_len(rest).map_err(|(k, message)| fail_at(&mut lines, pos + k, message))?;
            // urdf-rs's XML reader ends a DOCTYPE at its first `>`, and would read
            // what follows, a comment or literal of the internal subset, as elements
            // that no scan has counted. Neither URDF nor MJCF readers use a DTD.
            if let Some(k) = rest[..len - 1].find('>') {
                return Err(fail_at(
                    &mut lines,
                    pos + k,
                    "a `>` inside the <!DOCTYPE> (in a declaration, comment or literal of its internal subset);                      robot description readers use no DTD, so remove the internal subset `[...]` or the whole                      <!DOCTYPE>"
                        .into(),
                ));
            }
            pos += len;
        } else if rest.starts_with("<!") {
            let shown: String = rest
                .chars()
                .take(12)
                .take_while(|&c| c != '>' && !is_xml_space(c))
                .collect();
            return Err(fail(format!(
                "`{shown}` is not XML markup: `<!--` starts a comment, `<![CDATA[` a CDATA section, \
                 `<!DOCTYPE` the document type (write `&lt;` for a literal `<`)"
            )));
        } else if let Some(after) = rest.strip_prefix("</") {
            let end = after.find('>').ok_or_else(|| fail("end tag is never closed".into()))?;
            let name = after[..end].trim_matches(is_xml_space);
            match open.pop() {
                Some((opened, k)) if opened == name => {
                    tags[k].span.end = pos + 2 + end + 1;
                    if open.is_empty() {
                        closed_root = Some((opened, tags[k].line));
                    }
                }
                Some((opened, k)) => {
                    return Err(fail(format!(
                        "</{}> closes <{}> opened on line {}",
                        shorten(name),
                        shorten(&opened),
                        tags_line(&tags, k)
                    )))
                }
                None => return Err(fail(format!("</{}> has no matching start tag", shorten(name)))),
            }
            pos += 2 + end + 1;
        } else {
            let (tag, self_closing, len) =
                start_tag(rest).map_err(|(k, message)| fail_at(&mut lines, pos + k, message))?;
            let name = tag.0;
            if let Some((root, root_line)) = &closed_root {
                return Err(fail(format!(
                    "a second document element <{}> after <{}> (line {root_line}) closed; an XML document \
                     has exactly one, so put everything inside <{}>",
                    shorten(&name),
                    shorten(root),
                    shorten(root)
                )));
            }
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
            if self_closing {
                if parent.is_none() {
                    closed_root = Some((name, line));
                }
            } else {
                if open.len() >= MAX_DEPTH {
                    return Err(SyntaxError {
                        line,
                        message: format!(
                            "<{}> is nested more than {MAX_DEPTH} elements deep; a URDF needs fewer than 10 levels",
                            shorten(&name)
                        ),
                        too_deep: Some(shorten(&name)),
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
            message: format!("<{}> is never closed", shorten(&name)),
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

/// XML's white space: space, tab, carriage return, line feed.
pub(crate) fn is_xml_space(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\r' | '\n')
}

/// At most 40 characters of `s`, for messages about what may be huge.
pub(crate) fn shorten(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((k, _)) => format!("{}…", &s[..k]),
        None => s.to_string(),
    }
}

/// The first character XML does not allow in a document (control characters but
/// tab, carriage return and line feed; U+FFFE, U+FFFF), with its byte offset.
fn forbidden_char(text: &str) -> Option<(usize, char)> {
    let control = text
        .bytes()
        .position(|b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r'));
    // U+FFFE and U+FFFF are EF BF BE and EF BF BF in UTF-8.
    let nonchar = text.find(['\u{fffe}', '\u{ffff}']);
    let at = match (control, nonchar) {
        (Some(a), Some(b)) => a.min(b),
        (a, b) => a.or(b)?,
    };
    text[at..].chars().next().map(|c| (at, c))
}

/// Whether XML allows `c` in a document (as text or as a character reference).
fn is_xml_char(c: char) -> bool {
    !(c < ' ' && !matches!(c, '\t' | '\n' | '\r') || c == '\u{fffe}' || c == '\u{ffff}')
}

/// `U+0000 (NUL)` and the like, for messages.
fn describe_char(c: char) -> String {
    let what = match c {
        '\0' => " (NUL)",
        '\r' => " (carriage return)",
        '\n' => " (line feed)",
        '\t' => " (tab)",
        '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' => {
            " (a text-direction control)"
        }
        '\u{2028}' | '\u{2029}' => " (a line or paragraph separator)",
        c if c.is_control() => " (a control character)",
        _ => "",
    };
    format!("the character U+{:04X}{what}", c as u32)
}

/// Why a name cannot be a name: too long, empty of visible text, or holding a
/// control, a text-direction control or a line separator, which would make the
/// generated code, its documentation and any table of names lie about the text.
pub fn name_problem(name: &str) -> Option<String> {
    let count = name.chars().count();
    if count > MAX_NAME_CHARS {
        return Some(format!(
            "has {count} characters, more than the {MAX_NAME_CHARS} a name may have; give it a short name"
        ));
    }
    let bad = name.chars().find(|&c| {
        c.is_control()
            || matches!(c, '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{2028}' | '\u{2029}')
    })?;
    Some(format!(
        "holds {}; a name must be printable text on one line, such as `link_1`",
        describe_char(bad)
    ))
}

/// The byte length of a `<!DOCTYPE ...>` at the start of `s`, internal subset
/// `[...]` included, or where and why it cannot be read. Quoted literals,
/// comments and processing instructions may hold `>`, `[` and `]`.
fn doctype_len(s: &str) -> Result<usize, (usize, String)> {
    let b = s.as_bytes();
    let unclosed = |what: &str| (0, format!("{what} is never closed"));
    // The end of the quoted literal starting at `i`.
    let literal = |i: usize| -> Result<usize, (usize, String)> {
        let q = b[i] as char;
        s[i + 1..].find(q).map(|k| i + 1 + k + 1).ok_or_else(|| {
            (
                i,
                format!("a literal opened with {q} in the <!DOCTYPE> is never closed"),
            )
        })
    };
    let mut i = "<!DOCTYPE".len();
    let mut subset = false;
    while i < b.len() {
        match b[i] {
            b'"' | b'\'' => i = literal(i)?,
            b'>' => return Ok(i + 1),
            b'[' if !subset => {
                subset = true;
                i += 1;
                // The internal subset: declarations, comments, processing
                // instructions, parameter-entity references, up to `]`.
                loop {
                    while i < b.len() && is_xml_space(b[i] as char) {
                        i += 1;
                    }
                    let rest = &s[i..];
                    if rest.is_empty() {
                        return Err(unclosed("the <!DOCTYPE>'s internal subset `[`"));
                    }
                    if rest.starts_with(']') {
                        i += 1;
                        break;
                    }
                    if rest.starts_with("<!--") {
                        i += rest
                            .find("-->")
                            .ok_or((i, "a comment in the <!DOCTYPE> is never closed".to_string()))?
                            + 3;
                    } else if rest.starts_with("<?") {
                        i += rest.find("?>").ok_or((
                            i,
                            "a processing instruction in the <!DOCTYPE> is never closed".to_string(),
                        ))? + 2;
                    } else if rest.starts_with("<!") {
                        let start = i;
                        i += 2;
                        loop {
                            match b.get(i) {
                                None => return Err((start, "a declaration in the <!DOCTYPE> is never closed".into())),
                                Some(b'"' | b'\'') => i = literal(i)?,
                                Some(b'>') => {
                                    i += 1;
                                    break;
                                }
                                Some(b'<') => {
                                    return Err((i, "a `<` inside a declaration of the <!DOCTYPE>".into()));
                                }
                                Some(_) => i += 1,
                            }
                        }
                    } else if let Some(reference) = rest.strip_prefix('%') {
                        let name_len = reference.find(|c: char| !is_name_char(c)).unwrap_or(reference.len());
                        if name_len == 0 || !reference[name_len..].starts_with(';') {
                            return Err((
                                i,
                                "a `%` in the <!DOCTYPE> that starts no parameter-entity reference".into(),
                            ));
                        }
                        i += 1 + name_len + 1;
                    } else {
                        let c = rest.chars().next().unwrap_or(' ');
                        return Err((
                            i,
                            format!(
                                "unexpected `{c}` in the <!DOCTYPE>'s internal subset, which holds only declarations \
                                 such as <!ENTITY ...>, comments and processing instructions up to `]`"
                            ),
                        ));
                    }
                }
            }
            c if subset && !is_xml_space(c as char) => {
                return Err((
                    i,
                    format!(
                        "unexpected `{}` after the internal subset `[...]` of the <!DOCTYPE>, which ends with `>`",
                        s[i..].chars().next().unwrap_or(' ')
                    ),
                ))
            }
            b'<' => {
                return Err((
                    i,
                    "a `<` inside the <!DOCTYPE> outside its internal subset `[...]`".into(),
                ))
            }
            _ => i += 1,
        }
    }
    Err(unclosed("<!DOCTYPE"))
}

/// A character of an XML name (loosely: letters, digits and `_ : . -`, and all
/// non-ASCII).
fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | ':' | '.' | '-') || !c.is_ascii()
}

type StartTag = (String, Vec<(String, String)>);

/// Reads a start tag at the beginning of `s` (which starts with `<`): its name and
/// attributes, whether it is self-closing, and its length in bytes; or the byte
/// offset in `s` and the reason it cannot be read.
fn start_tag(s: &str) -> Result<(StartTag, bool, usize), (usize, String)> {
    let is_delim = |c: char| is_xml_space(c) || c == '/' || c == '>';
    let body = &s[1..];
    let name_len = body.find(is_delim).unwrap_or(body.len());
    let name = &body[..name_len];
    if name.is_empty() || name.contains(['<', '&', '"', '\'', '=']) {
        return Err((0, "a `<` that starts no tag (write `&lt;` for a literal `<`)".into()));
    }
    let shown = shorten(name);
    let unclosed = || (0, format!("tag <{shown}> is never closed"));
    let mut attrs: Vec<(String, String)> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut i = 1 + name_len;
    loop {
        let rest = &s[i..];
        let trimmed = rest.trim_start_matches(is_xml_space);
        let spaced = trimmed.len() < rest.len();
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
        if trimmed.starts_with('<') {
            return Err((i, format!("tag <{shown}> is never closed before the next `<`")));
        }
        // The attribute's name ends at `=`, white space, `/` or `>`.
        let attr_len = trimmed.find(|c: char| c == '=' || is_delim(c)).unwrap_or(trimmed.len());
        let attr = &trimmed[..attr_len];
        if attr.is_empty() || !spaced || attr.contains(['<', '"', '\'']) {
            return Err((
                i,
                format!("malformed attribute in <{shown}>; write attributes as name=\"value\""),
            ));
        }
        let after = &trimmed[attr_len..];
        let eq = after.trim_start_matches(is_xml_space);
        let Some(value) = eq.strip_prefix('=') else {
            return Err((
                i,
                format!(
                    "attribute `{}` of <{shown}> has no value; write {0}=\"value\"",
                    shorten(attr)
                ),
            ));
        };
        let value = value.trim_start_matches(is_xml_space);
        let value_at = i + (trimmed.len() - value.len());
        let quote = value.chars().next().filter(|&c| c == '"' || c == '\'');
        let quote = quote.ok_or_else(|| {
            (
                value_at,
                format!("attribute `{}` of <{shown}> needs a quoted value", shorten(attr)),
            )
        })?;
        let close = value[1..].find(quote).ok_or_else(unclosed)?;
        let raw = &value[1..1 + close];
        if let Some(k) = raw.find('<') {
            return Err((
                value_at + 1 + k,
                format!("a `<` in attribute `{}` of <{shown}>; write `&lt;`", shorten(attr)),
            ));
        }
        let resolved = unescape_checked(raw).map_err(|(k, message)| {
            (
                value_at + 1 + k,
                format!("{message} in attribute `{}` of <{shown}>", shorten(attr)),
            )
        })?;
        // A set once there are many attributes, so that checking stays linear.
        if attrs.len() == 16 {
            seen = attrs.iter().map(|(a, _)| a.clone()).collect();
        }
        let repeated = if attrs.len() < 16 {
            attrs.iter().any(|(a, _)| a == attr)
        } else {
            !seen.insert(attr.to_string())
        };
        if repeated {
            return Err((i, format!("attribute `{}` of <{shown}> is given twice", shorten(attr))));
        }
        if NAME_ATTRIBUTES.contains(&attr) {
            if let Some(problem) = name_problem(&resolved) {
                return Err((
                    value_at,
                    format!(
                        "the {attr} of <{shown} {attr}=\"{}\"> {problem}",
                        shorten(&resolved).escape_debug()
                    ),
                ));
            }
        }
        attrs.push((attr.to_string(), resolved));
        i = value_at + 1 + close + 1;
    }
}

/// The reference at the start of `s` (which starts with `&`): the character it
/// stands for and its length, if it is one of XML's five predefined entities or a
/// character reference to a character XML allows. Looks at most a few bytes ahead,
/// so a run of `&` costs linear time.
fn reference(s: &str) -> Option<(char, usize)> {
    // `&#x10FFFF;` and `&quot;` are short; 32 bytes allow leading zeros.
    let end = s.as_bytes().iter().skip(1).take(32).position(|&b| b == b';')?;
    let body = &s[1..1 + end];
    let c = match body {
        "lt" => '<',
        "gt" => '>',
        "amp" => '&',
        "quot" => '"',
        "apos" => '\'',
        e => {
            let code = match e.strip_prefix("#x") {
                Some(h) if !h.is_empty() && h.bytes().all(|b| b.is_ascii_hexdigit()) => {
                    u32::from_str_radix(h, 16).ok()?
                }
                Some(_) => return None,
                None => {
                    let d = e.strip_prefix('#')?;
                    if d.is_empty() || !d.bytes().all(|b| b.is_ascii_digit()) {
                        return None;
                    }
                    d.parse().ok()?
                }
            };
            char::from_u32(code).filter(|&c| is_xml_char(c))?
        }
    };
    Some((c, 1 + end + 1))
}

/// Checks that every `&` in `s` starts a reference [`reference`] reads: where the
/// first that does not is, and why.
fn check_references(s: &str) -> Result<(), (usize, String)> {
    let mut at = 0;
    while let Some(k) = s[at..].find('&') {
        at += k;
        match reference(&s[at..]) {
            Some((_, len)) => at += len,
            None => return Err((at, bad_reference(&s[at..]))),
        }
    }
    Ok(())
}

fn bad_reference(s: &str) -> String {
    let shown: String = s
        .chars()
        .take(12)
        .take_while(|&c| c != ';' && !is_xml_space(c))
        .collect();
    format!(
        "`{shown}` is not an entity reference XML knows without a DTD (`&lt;` `&gt;` `&amp;` `&quot;` `&apos;`, or a \
         character reference such as `&#38;`); write `&amp;` for a literal `&`"
    )
}

/// [`unescape`], refusing an `&` that starts no known reference: its byte offset
/// and why.
fn unescape_checked(s: &str) -> Result<String, (usize, String)> {
    if !s.contains('&') {
        return Ok(s.to_string());
    }
    let mut out = String::with_capacity(s.len());
    let mut at = 0;
    while let Some(k) = s[at..].find('&') {
        out.push_str(&s[at..at + k]);
        at += k;
        let (c, len) = reference(&s[at..]).ok_or_else(|| (at, bad_reference(&s[at..])))?;
        out.push(c);
        at += len;
    }
    out.push_str(&s[at..]);
    Ok(out)
}

/// Resolves the predefined XML entities and character references, so that names
/// compare equal to what urdf-rs reads; an `&` that starts neither is kept.
pub fn unescape(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len());
    let mut at = 0;
    while let Some(k) = s[at..].find('&') {
        out.push_str(&s[at..at + k]);
        at += k;
        match reference(&s[at..]) {
            Some((c, len)) => {
                out.push(c);
                at += len;
            }
            None => {
                out.push('&');
                at += 1;
            }
        }
    }
    out.push_str(&s[at..]);
    out
}

/// The 1-based line of byte offset `at` (`\r\n`, `\r` and `\n` each end a line).
pub fn line_of(text: &str, at: usize) -> usize {
    LineCounter::new(text).line_at(at)
}

/// 1-based line numbers of byte offsets, for offsets visited in increasing order.
/// `\r\n`, `\r` alone and `\n` alone each end one line.
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
        let pos = pos.min(self.text.len());
        if pos <= self.pos {
            return self.line;
        }
        let b = self.text.as_bytes();
        for i in self.pos..pos {
            // A `\r` ends a line unless a `\n` follows, which ends it instead.
            if b[i] == b'\n' || (b[i] == b'\r' && b.get(i + 1) != Some(&b'\n')) {
                self.line += 1;
            }
        }
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
        let e = scan("<robot>\n<!-->\n</robot>").unwrap_err();
        assert_eq!(e.line, 2);
        let e = scan("<robot>\n<!-- a -- b -->\n</robot>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("`--` inside a comment"), "{}", e.message);
        let e = scan("<?pi ?x>\n<robot>\n</robot> ?>").unwrap_err();
        assert!(
            e.message.contains("a `>` inside a processing instruction"),
            "{}",
            e.message
        );
        assert!(scan("<?xml version='1.0'?><!----><robot><?pi?><![CDATA[]]]]></robot>").is_ok());
        let e = scan("<robot>\n<!-- open\n</robot>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.starts_with("comment is never closed"), "{}", e.message);
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
        assert_eq!(unescape("&&#0;&#xD800;&"), "&&#0;&#xD800;&");
    }

    #[test]
    fn doctype_with_internal_subset_is_skipped_whole() {
        for doctype in [
            "<!DOCTYPE r>",
            "<!DOCTYPE r [ ] >",
            "<!DOCTYPE r SYSTEM \"a.dtd\">",
            "<!DOCTYPE r PUBLIC '-//x//y' \"u\" [\n %p;\n]>",
        ] {
            let text = format!("{doctype}\n<robot><link name='a'/></robot>");
            let tags = scan(&text).unwrap_or_else(|e| panic!("{doctype}: {e:?}"));
            assert_eq!(tags.len(), 2, "{doctype}");
            assert_eq!(tags[0].line, doctype.lines().count() + 1, "{doctype}");
        }
        for (doctype, needle) in [
            (
                "<!DOCTYPE r [ <!ENTITY e 'x'> ",
                "unexpected `<` in the <!DOCTYPE>'s internal subset",
            ),
            ("<!DOCTYPE r [ <!-- ", "never closed"),
            ("<!DOCTYPE r [ x ]>", "unexpected `x`"),
            ("<!DOCTYPE r \"open>", "never closed"),
            ("<!DOCTYPE a><!DOCTYPE b>", "at most one"),
            ("<!DOCTYPE r [ <!ENTITY e \"]><a>\"> ]>", "a `>` inside the <!DOCTYPE>"),
            ("<!DOCTYPE r [ <!-- <a> --> ]>", "a `>` inside the <!DOCTYPE>"),
            ("<!DOCTYPE r [ <?pi <a> ?> ]>", "a `>` inside the <!DOCTYPE>"),
        ] {
            let text = format!("{doctype}<robot>{}{}</robot>", "<a>".repeat(300), "</a>".repeat(300));
            let e = scan(&text).unwrap_err();
            assert!(e.message.contains(needle), "{doctype}: {}", e.message);
        }
        // Whatever the DOCTYPE, the nesting limit applies after it.
        let text = format!(
            "<!DOCTYPE r [ ] >\n<robot>{}{}</robot>",
            "<a>".repeat(300),
            "</a>".repeat(300)
        );
        assert_eq!(scan(&text).unwrap_err().too_deep.as_deref(), Some("a"));
    }

    #[test]
    fn line_ends_of_every_kind_count_once() {
        let tags = scan("<robot>\r<a/>\r\n<b/>\n<c/>\r\r<d/></robot>").unwrap();
        let lines: Vec<usize> = tags.iter().map(|t| t.line).collect();
        assert_eq!(lines, [1, 2, 3, 4, 6]);
        let e = scan("<robot>\r\r<a name='x\0'/></robot>").unwrap_err();
        assert_eq!(e.line, 3);
        assert!(e.message.contains("U+0000 (NUL)"), "{}", e.message);
        assert_eq!(line_of("a\rb\r\nc\nd", 8), 4);
    }

    #[test]
    fn one_document_element_and_no_stray_markup() {
        let e = scan("<robot/>\n<robot/>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("second document element <robot>"), "{}", e.message);
        let e = scan("<robot></robot>\n\n<x></x>").unwrap_err();
        assert_eq!(e.line, 3);
        let e = scan("<robot/>\ntrailing").unwrap_err();
        assert_eq!(e.line, 2);
        let e = scan("<robot>\n<!x></robot>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("`<!x` is not XML markup"), "{}", e.message);
        assert!(scan("\u{feff}<robot/>").is_ok());
    }

    #[test]
    fn every_ampersand_starts_a_reference() {
        let e = scan("<robot>\n<link name='a' x='&&'/></robot>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("write `&amp;`"), "{}", e.message);
        assert!(e.message.contains("attribute `x` of <link>"), "{}", e.message);
        assert!(scan("<robot><link name='a&#0;'/></robot>").is_err());
        assert!(scan("<robot>\n\nR&amp;D &bogus;</robot>").unwrap_err().line == 3);
        let tags = scan("<robot name='&#x41;&#66;&lt;'/>").unwrap();
        assert_eq!(tags[0].attr("name"), Some("AB<"));
    }

    #[test]
    fn names_are_short_printable_text() {
        let long = format!("<robot>\n<link name='{}'/></robot>", "x".repeat(MAX_NAME_CHARS + 1));
        let e = scan(&long).unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("more than the 1024"), "{}", e.message);
        assert!(e.message.len() < 300, "{}", e.message);
        let ok = format!("<robot><link name='{}'/></robot>", "é".repeat(MAX_NAME_CHARS));
        assert!(scan(&ok).is_ok());
        for bad in ["a&#13;b", "a\u{202e}b", "a\u{2066}b", "a&#x85;b", "a\tb"] {
            let e = scan(&format!("<robot>\n<joint name='{bad}'/></robot>")).unwrap_err();
            assert_eq!(e.line, 2, "{bad}");
            assert!(e.message.contains("the name of <joint"), "{bad}: {}", e.message);
        }
    }
}
