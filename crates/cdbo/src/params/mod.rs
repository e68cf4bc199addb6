//! Reader for TORCS / Speed Dreams parameter files (`<params>`, `<section>`, `<attnum>`,
//! `<attstr>`), the format of every track and car file.
//!
//! External entities declared in the DOCTYPE (`<!ENTITY default-surfaces SYSTEM "...">`) are
//! resolved relative to the file, as TORCS does; a missing entity file is skipped with a
//! warning, and so is an entity used without being declared (TORCS's e-track-4 uses
//! `&default-objects;` that way). Numbers are converted to SI through their `unit` attribute
//! ([`units`]).
//!
//! Files are read as bytes and decoded as UTF-8, or as Latin-1 where they are not valid UTF-8:
//! TORCS's own `data/tracks/objects.xml` declares UTF-8 but holds a Latin-1 `é` in a comment,
//! and the game reads it. Latin-1 maps every byte to a character, so nothing is refused; the
//! fallback is silent because it is what the game does with the same file.

pub mod units;

use std::path::Path;
use std::sync::Arc;

use crate::bounded::{self, Bound};
use crate::error::{Error, Result};

/// A value of an attribute, already converted to SI for numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// An `<attnum>`, in SI units.
    Num(f64),
    /// An `<attstr>`.
    Str(String),
}

/// One `<attnum>` or `<attstr>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Attr {
    /// The `name` attribute.
    pub name: String,
    /// The value.
    pub value: Value,
    /// 1-based line in its file.
    pub line: u32,
    /// The file it was read from: after a [`Section::merge`], the car's or its category's.
    pub file: Arc<str>,
}

/// One `<section>` (or the `<params>` root), with its attributes and sub-sections in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Section {
    /// The `name` attribute.
    pub name: String,
    /// Slash-separated path from the root, used in error messages.
    pub path: String,
    /// 1-based line in its file.
    pub line: u32,
    /// The file it was read from (after a [`Section::merge`], the overlay's where it has the
    /// section).
    pub file: Arc<str>,
    /// Attributes in file order.
    pub attrs: Vec<Attr>,
    /// Sub-sections in file order.
    pub sections: Vec<Section>,
}

/// A parsed parameter file.
#[derive(Debug, Clone)]
pub struct Params {
    /// The file name used in messages.
    pub file: String,
    /// The `<params>` element.
    pub root: Section,
    /// Non-fatal problems met while reading (e.g. a missing entity file).
    pub warnings: Vec<String>,
}

impl Params {
    /// Reads and parses a file, a `bound` kind of file ([`crate::bounded`]), resolving its
    /// external entities relative to its folder (each an [`bounded::ENTITY_FILE`]).
    pub fn read(path: &Path, bound: &Bound) -> Result<Params> {
        let text = read_text(path, bound)?;
        Params::parse(&text, &path.display().to_string(), path.parent())
    }

    /// Parses text; `dir` is where relative entity paths are resolved (`None`: skip them).
    pub fn parse(text: &str, file: &str, dir: Option<&Path>) -> Result<Params> {
        let mut warnings = Vec::new();
        let expanded = expand_entities(text, file, dir, &mut warnings)?;
        let doc = roxmltree::Document::parse(&expanded).map_err(|e| Error::Parse {
            file: file.to_owned(),
            line: Some(e.pos().row),
            element: "XML".to_owned(),
            message: e.to_string(),
        })?;
        let root = doc.root_element();
        if root.tag_name().name() != "params" {
            return Err(Error::Parse {
                file: file.to_owned(),
                line: Some(doc.text_pos_at(root.range().start).row),
                element: format!("<{}>", root.tag_name().name()),
                message: "the root element must be <params>".to_owned(),
            });
        }
        let lines = LineIndex::new(&expanded);
        let root = read_section(&lines, root, "", &Arc::from(file))?;
        Ok(Params {
            file: file.to_owned(),
            root,
            warnings,
        })
    }

    /// An error about an element of this file.
    pub fn error(&self, element: &str, line: Option<u32>, message: impl Into<String>) -> Error {
        Error::Parse {
            file: self.file.clone(),
            line,
            element: element.to_owned(),
            message: message.into(),
        }
    }

    /// The section at a slash-separated path below the root, e.g. `Main Track/Track Segments`.
    pub fn section(&self, path: &str) -> Option<&Section> {
        self.root.section(path)
    }

    /// A required section.
    pub fn require_section(&self, path: &str) -> Result<&Section> {
        self.section(path)
            .ok_or_else(|| self.error(path, None, "missing section"))
    }
}

impl Section {
    /// The sub-section at a slash-separated path.
    pub fn section(&self, path: &str) -> Option<&Section> {
        let mut cur = self;
        for part in path.split('/').filter(|p| !p.is_empty()) {
            cur = cur.sections.iter().find(|s| s.name == part)?;
        }
        Some(cur)
    }

    /// Overlays `over` on this section, as TORCS merges a car file over its category file:
    /// attributes of `over` replace those of the same name, sub-sections merge by name. Each
    /// attribute keeps the file and line it came from, so that an error about its value names
    /// the right file; a section present in both points at `over`'s.
    pub fn merge(&mut self, over: &Section) {
        self.file = over.file.clone();
        self.line = over.line;
        for a in &over.attrs {
            match self.attrs.iter_mut().find(|b| b.name == a.name) {
                Some(b) => *b = a.clone(),
                None => self.attrs.push(a.clone()),
            }
        }
        for s in &over.sections {
            match self.sections.iter_mut().find(|t| t.name == s.name) {
                Some(t) => t.merge(s),
                None => self.sections.push(s.clone()),
            }
        }
    }

    /// The line of the attribute called `name`, or of the section when it has none: where an
    /// error about that value points.
    pub fn line_of(&self, name: &str) -> u32 {
        self.attr(name).map_or(self.line, |a| a.line)
    }

    /// An error about the value of the attribute called `name` (or about the section, when it
    /// has none), naming the file and line the value came from.
    pub fn value_error(&self, name: &str, message: impl Into<String>) -> Error {
        let (file, line) = self
            .attr(name)
            .map_or((&self.file, self.line), |a| (&a.file, a.line));
        Error::Parse {
            file: file.to_string(),
            line: Some(line),
            element: format!("{}/{}", self.path, name),
            message: message.into(),
        }
    }

    /// An error about this section (`element` names it or a part of it), at its own file and
    /// line.
    pub fn error(&self, element: &str, message: impl Into<String>) -> Error {
        Error::Parse {
            file: self.file.to_string(),
            line: Some(self.line),
            element: element.to_owned(),
            message: message.into(),
        }
    }

    /// The attribute called `name`, if any.
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }

    /// A number attribute in SI units, `Ok(None)` when absent, an error naming the attribute's
    /// own file and line when it is a string.
    pub fn num(&self, name: &str) -> Result<Option<f64>> {
        match self.attr(name) {
            None => Ok(None),
            Some(Attr {
                value: Value::Num(v),
                ..
            }) => Ok(Some(*v)),
            Some(Attr {
                value: Value::Str(s),
                ..
            }) => Err(self.value_error(
                name,
                format!("expected a number (<attnum>), found the string {s:?}"),
            )),
        }
    }

    /// A number attribute, or `default` when absent.
    pub fn num_or(&self, name: &str, default: f64) -> Result<f64> {
        Ok(self.num(name)?.unwrap_or(default))
    }

    /// A required number attribute.
    pub fn require_num(&self, name: &str) -> Result<f64> {
        self.num(name)?
            .ok_or_else(|| self.value_error(name, "missing required attribute"))
    }

    /// A string attribute (a number attribute is not accepted).
    pub fn str(&self, name: &str) -> Option<&str> {
        match self.attr(name) {
            Some(Attr {
                value: Value::Str(s),
                ..
            }) => Some(s),
            _ => None,
        }
    }
}

fn read_section(
    lines: &LineIndex,
    node: roxmltree::Node,
    parent: &str,
    file: &Arc<str>,
) -> Result<Section> {
    let line = lines.line(node.range().start);
    let name = node.attribute("name").unwrap_or_default().to_owned();
    let path = match (parent.is_empty(), node.tag_name().name() == "params") {
        (_, true) => String::new(),
        (true, false) => name.clone(),
        (false, false) => format!("{parent}/{name}"),
    };
    let mut section = Section {
        name,
        path,
        line,
        file: file.clone(),
        ..Section::default()
    };
    for child in node.children().filter(|c| c.is_element()) {
        let line = lines.line(child.range().start);
        let tag = child.tag_name().name();
        let element = |n: &str| {
            if section.path.is_empty() {
                n.to_owned()
            } else {
                format!("{}/{}", section.path, n)
            }
        };
        let invalid = |element: String, message: String| Error::Parse {
            file: file.to_string(),
            line: Some(line),
            element,
            message,
        };
        match tag {
            "section" => {
                let sub = read_section(lines, child, &section.path, file)?;
                section.sections.push(sub);
            }
            "attnum" | "attstr" => {
                let name = child.attribute("name").ok_or_else(|| {
                    invalid(
                        element(&format!("<{tag}>")),
                        "missing the name attribute".to_owned(),
                    )
                })?;
                let val = child.attribute("val").ok_or_else(|| {
                    invalid(element(name), "missing the val attribute".to_owned())
                })?;
                let value = if tag == "attnum" {
                    let v = parse_number(val).ok_or_else(|| {
                        invalid(element(name), format!("val {val:?} is not a number"))
                    })?;
                    if !v.is_finite() {
                        return Err(invalid(element(name), format!("val {val:?} is not finite")));
                    }
                    let unit = child.attribute("unit").unwrap_or("");
                    let factor = units::si_factor(unit)
                        .ok_or_else(|| invalid(element(name), format!("unknown unit {unit:?}")))?;
                    Value::Num(v * factor)
                } else {
                    Value::Str(val.to_owned())
                };
                section.attrs.push(Attr {
                    name: name.to_owned(),
                    value,
                    line,
                    file: file.clone(),
                });
            }
            _ => {} // unknown elements are ignored, as TORCS does
        }
    }
    Ok(section)
}

/// Byte offsets of line starts, for O(log n) line numbers (roxmltree's own is O(n)).
struct LineIndex(Vec<usize>);

impl LineIndex {
    fn new(text: &str) -> LineIndex {
        LineIndex(
            std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        )
    }

    /// The 1-based line of a byte offset.
    fn line(&self, byte: usize) -> u32 {
        self.0.partition_point(|&start| start <= byte) as u32
    }
}

/// Removes the DOCTYPE and substitutes its external entities.
///
/// Line numbers of the main file are kept: the DOCTYPE becomes as many blank lines, and an
/// included file's line breaks become spaces.
fn expand_entities(
    text: &str,
    file: &str,
    dir: Option<&Path>,
    warnings: &mut Vec<String>,
) -> Result<String> {
    let Some(start) = text.find("<!DOCTYPE") else {
        return skip_undeclared(text.to_owned(), &[], file, text, 0, warnings);
    };
    let end = doctype_end(text, start).ok_or_else(|| Error::Parse {
        file: file.to_owned(),
        line: Some(line_of(text, start)),
        element: "<!DOCTYPE>".to_owned(),
        message: "unterminated DOCTYPE".to_owned(),
    })?;
    let doctype = &text[start..end];
    let mut entities: Vec<(String, String)> = Vec::new();
    let mut rest = doctype;
    while let Some(i) = rest.find("<!ENTITY") {
        let decl_end = rest[i..].find('>').map(|j| i + j).unwrap_or(rest.len());
        let decl = &rest[i + "<!ENTITY".len()..decl_end];
        let mut words = decl.split_whitespace();
        let name = words.next().unwrap_or_default().to_owned();
        let quoted: Vec<&str> = decl.split(['"', '\'']).collect();
        let content = if decl.contains("SYSTEM") {
            let rel = quoted.get(1).copied().unwrap_or_default();
            match dir.map(|d| d.join(rel)) {
                Some(p) if p.is_file() => {
                    let body = read_text(&p, &bounded::ENTITY_FILE)?;
                    strip_xml_decl(&body).replace(['\n', '\r'], " ")
                }
                Some(p) => {
                    warnings.push(format!(
                        "{file}: entity &{name}; file {} not found, skipped",
                        p.display()
                    ));
                    String::new()
                }
                None => {
                    warnings.push(format!(
                        "{file}: entity &{name}; ({rel}) not resolved, skipped"
                    ));
                    String::new()
                }
            }
        } else {
            quoted.get(1).copied().unwrap_or_default().to_owned()
        };
        entities.push((name, content));
        rest = &rest[decl_end..];
    }
    let mut out = String::with_capacity(text.len());
    out.push_str(&text[..start]);
    out.extend(std::iter::repeat_n('\n', doctype.matches('\n').count()));
    let mut body = text[end..].to_owned();
    for (name, content) in &entities {
        body = body.replace(&format!("&{name};"), content);
        if body.len() > MAX_EXPANDED_BYTES {
            return Err(Error::Parse {
                file: file.to_owned(),
                line: None,
                element: format!("&{name};"),
                message: format!(
                    "the entities expand the file past {} MiB",
                    MAX_EXPANDED_BYTES >> 20
                ),
            });
        }
    }
    out.push_str(&body);
    let declared: Vec<&str> = entities.iter().map(|(n, _)| n.as_str()).collect();
    skip_undeclared(out, &declared, file, text, start, warnings)
}

/// Largest text accepted once entities are expanded (a guard against entities that
/// multiply each other).
const MAX_EXPANDED_BYTES: usize = 64 << 20;

/// Removes references to entities that are neither declared nor predefined (`&amp;` ...) nor
/// character references, with one warning each: TORCS skips them, an XML parser would stop.
/// `original` is the file as read, searched for the reference's line (after `from`, where
/// its DOCTYPE starts).
fn skip_undeclared(
    expanded: String,
    declared: &[&str],
    file: &str,
    original: &str,
    from: usize,
    warnings: &mut Vec<String>,
) -> Result<String> {
    const PREDEFINED: [&str; 5] = ["amp", "lt", "gt", "quot", "apos"];
    let mut undeclared: Vec<String> = Vec::new();
    let mut rest = expanded.as_str();
    while let Some(i) = rest.find('&') {
        let after = &rest[i + 1..];
        let len = after
            .find(|c: char| !(c.is_alphanumeric() || matches!(c, '-' | '.' | '_' | ':')))
            .unwrap_or(after.len());
        if after[len..].starts_with(';') && is_xml_name(&after[..len]) {
            let name = &after[..len];
            if !PREDEFINED.contains(&name)
                && !declared.contains(&name)
                && !undeclared.iter().any(|u| u == name)
            {
                undeclared.push(name.to_owned());
            }
        }
        rest = after;
    }
    if undeclared.is_empty() {
        return Ok(expanded);
    }
    let mut out = expanded;
    for name in &undeclared {
        let reference = format!("&{name};");
        let line = original[from..]
            .find(&reference)
            .map(|i| format!(":{}", line_of(original, from + i)))
            .unwrap_or_default();
        warnings.push(format!(
            "{file}{line}: entity {reference} is used but not declared, skipped (as TORCS does)"
        ));
        out = out.replace(&reference, "");
    }
    Ok(out)
}

/// An XML name as an entity reference uses it: a letter, `_` or `:` then letters, digits,
/// `-`, `.`, `_`, `:`.
fn is_xml_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_' || c == ':')
        && chars.all(|c| c.is_alphanumeric() || matches!(c, '-' | '.' | '_' | ':'))
}

/// Reads a file, a `bound` kind of file ([`crate::bounded`]), as text: UTF-8, or Latin-1
/// where it is not valid UTF-8 (see the module doc).
pub fn read_text(path: &Path, bound: &Bound) -> Result<String> {
    Ok(decode(bounded::read_file(path, bound)?))
}

/// Decodes bytes as UTF-8, or as Latin-1 (each byte the character of that code) when they are
/// not valid UTF-8.
pub fn decode(bytes: Vec<u8>) -> String {
    match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => e.into_bytes().iter().map(|&b| char::from(b)).collect(),
    }
}

/// A decimal number, or a hexadecimal integer such as `0x00FF00` (C's `strtod` reads both).
fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim();
    match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) => i64::from_str_radix(hex, 16).ok().map(|v| v as f64),
        None => t.parse().ok(),
    }
}

/// The byte just after the DOCTYPE starting at `start`, honouring an internal subset `[...]`.
fn doctype_end(text: &str, start: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in text[start..].char_indices() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.checked_sub(1)?,
            '>' if depth == 0 => return Some(start + i + 1),
            _ => {}
        }
    }
    None
}

fn strip_xml_decl(body: &str) -> &str {
    match (body.find("<?xml"), body.find("?>")) {
        (Some(s), Some(e)) if s < e => &body[e + 2..],
        _ => body,
    }
}

fn line_of(text: &str, byte: usize) -> u32 {
    text[..byte].matches('\n').count() as u32 + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = r#"<?xml version="1.0"?>
<!DOCTYPE params SYSTEM "x.dtd" [
<!ENTITY missing SYSTEM "does-not-exist.xml">
]>
<params name="t">
  <section name="A">&missing;
    <attnum name="len" unit="ft" val="10"/>
    <attstr name="kind" val="str"/>
    <section name="B"><attnum name="angle" unit="deg" val="90"/></section>
  </section>
</params>"#;

    #[test]
    fn reads_sections_units_and_lines() {
        let p = Params::parse(SAMPLE, "sample.xml", Some(Path::new("/nonexistent"))).unwrap();
        let a = p.section("A").unwrap();
        assert_eq!(a.line, 6);
        assert!((a.num("len").unwrap().unwrap() - 3.048).abs() < 1e-12);
        assert_eq!(a.str("kind"), Some("str"));
        let b = p.section("A/B").unwrap();
        assert_eq!(b.path, "A/B");
        assert!((b.require_num("angle").unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
    }

    /// A file and the entity file it includes are each read through their bound: a file
    /// past its bound is refused, naming it, what it is and the bound (a sparse file stands
    /// for a large one).
    #[test]
    fn a_file_or_an_included_entity_past_its_bound_is_refused() {
        let dir = crate::scratch::dir("params-bound");
        let big = dir.join("big.xml");
        std::fs::File::create(&big)
            .and_then(|f| f.set_len(bounded::ENTITY_FILE.bytes + 1))
            .unwrap();
        let including = SAMPLE.replace("does-not-exist.xml", "big.xml");
        let e = Params::parse(&including, "sample.xml", Some(&dir))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!(
                "{}: the included entity file is larger than its bound of 16 MiB",
                big.display()
            )
        );
        let e = Params::read(&big, &bounded::TRACK_FILE)
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("big.xml: the track file is larger than its bound of 16 MiB"));
    }

    #[test]
    fn errors_name_file_line_and_element() {
        let bad = SAMPLE.replace(r#"unit="ft""#, r#"unit="furlong""#);
        let e = Params::parse(&bad, "sample.xml", None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("sample.xml:7") && e.contains("A/len") && e.contains("furlong"),
            "{e}"
        );
        let bad = SAMPLE.replace(r#"val="10""#, r#"val="ten""#);
        let e = Params::parse(&bad, "sample.xml", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("A/len") && e.contains("ten"), "{e}");
        let truncated = &SAMPLE[..SAMPLE.len() - 40];
        let e = Params::parse(truncated, "sample.xml", None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("sample.xml:"), "{e}");
        let e = p_missing();
        assert!(e.contains("A/width") && e.contains("missing"), "{e}");
    }

    #[test]
    fn latin1_bytes_decode_as_latin1() {
        // TORCS's objects.xml: declared UTF-8, a Latin-1 é (0xE9) in a comment.
        let bytes =
            b"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- cr\xe9\xe9 -->\n<params/>".to_vec();
        let text = decode(bytes);
        assert!(text.contains("cr\u{e9}\u{e9}"), "{text}");
        assert!(Params::parse(&text, "o.xml", None).is_ok());
        assert_eq!(
            decode("d\u{e9}j\u{e0}".as_bytes().to_vec()),
            "d\u{e9}j\u{e0}"
        );
    }

    #[test]
    fn an_undeclared_entity_is_skipped_with_a_warning_naming_its_line() {
        let text = SAMPLE.replace(
            "<section name=\"B\">",
            "<section name=\"B\">&default-objects;",
        );
        let p = Params::parse(&text, "e.xml", None).unwrap();
        assert!(p.section("A/B").is_some());
        assert!(
            p.warnings
                .iter()
                .any(|w| w.starts_with("e.xml:9:") && w.contains("&default-objects;")),
            "{:?}",
            p.warnings
        );
        // Predefined and character references are XML's own, left to the parser.
        let p = Params::parse(
            r#"<params><attstr name="a" val="x &amp; y &#233;"/></params>"#,
            "p.xml",
            None,
        )
        .unwrap();
        assert_eq!(p.root.str("a"), Some("x & y \u{e9}"));
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    }

    fn p_missing() -> String {
        let p = Params::parse(SAMPLE, "sample.xml", None).unwrap();
        p.section("A")
            .unwrap()
            .require_num("width")
            .unwrap_err()
            .to_string()
    }
}
