//! The URDF rewritten with identified inertials: only the `<inertial>` elements of
//! the named links change; every other byte (comments, formatting, attribute order,
//! visuals, other links) is kept.
//!
//! Identification is per moving body, and a body is a link together with every link
//! hanging on it through fixed joints (merged, as the model builder lumps them). The
//! identified inertial of a body is in its own link's frame (a URDF link frame is
//! its joint frame), so it is written to that link. When the body lumped other
//! links, their share cannot be told apart: [`MergedLinks::Refuse`] (the default)
//! reports an error, [`MergedLinks::Lump`] writes the whole inertial to the body's
//! link and removes the `<inertial>` of each merged link (they become massless
//! frames), so the file describes the identified robot exactly.

use dyngen_model::xml::{scan, Tag};
use dyngen_model::{check_physical, inertial_element, Inertial};

use super::ReportError;

/// What to do when a body to update lumped links attached by fixed joints.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MergedLinks {
    /// Error [`ReportError::MergedLinks`] naming the link, its line and the merged links.
    #[default]
    Refuse,
    /// The body's link gets the whole lumped inertial; merged links lose their `<inertial>`.
    Lump,
}

/// [`rewrite_urdf_inertials_with`] with [`MergedLinks::Refuse`].
pub fn rewrite_urdf_inertials<S: AsRef<str>>(
    original_text: &str,
    updates: &[(S, Inertial)],
) -> Result<String, ReportError> {
    rewrite_urdf_inertials_with(original_text, updates, MergedLinks::Refuse)
}

/// Replaces the `<inertial>` of each named link by one holding `inertial`: `<origin
/// xyz="com" rpy="0 0 0"/>`, `<mass>`, and `<inertia>` about the centre of mass in
/// link axes (the symmetric part of `inertial.inertia`). A link without `<inertial>`
/// gets one right after its start tag, indented like its other children; a
/// self-closing `<link name="x"/>` is expanded. Numbers are written in Rust's
/// shortest round-trip form, so parsing the result gives back the same `f64`s.
///
/// Errors name the link and its line: not found, defined twice, not a moving body
/// of its own (merged into another, or part of the fixed base), or lumping merged
/// links under [`MergedLinks::Refuse`].
pub fn rewrite_urdf_inertials_with<S: AsRef<str>>(
    original_text: &str,
    updates: &[(S, Inertial)],
    merged: MergedLinks,
) -> Result<String, ReportError> {
    let doc = Document::scan(original_text)?;
    let newline = if original_text.contains("\r\n") { "\r\n" } else { "\n" };
    // Byte-range replacements, applied back to front.
    let mut edits: Vec<(std::ops::Range<usize>, String)> = Vec::new();
    let mut seen: Vec<&str> = Vec::new();
    for (name, inertial) in updates {
        let name = name.as_ref();
        if seen.contains(&name) {
            return Err(ReportError::DuplicateUpdate { link: name.into() });
        }
        seen.push(name);
        check_inertial(name, inertial)?;
        let k = doc.link(name)?;
        let link = &doc.tags[doc.links[k]];
        let group = doc.group(name);
        match group.body {
            Some(body) if body == name => {}
            body => {
                return Err(ReportError::NotABody {
                    link: name.into(),
                    line: link.line,
                    body: body.map(str::to_string),
                })
            }
        }
        if !group.merged.is_empty() {
            if merged == MergedLinks::Refuse {
                return Err(ReportError::MergedLinks {
                    link: name.into(),
                    line: link.line,
                    merged: group.merged.iter().map(|s| s.to_string()).collect(),
                });
            }
            for m in &group.merged {
                let ml = doc.link(m)?;
                if let Some(i) = doc.child(doc.links[ml], "inertial") {
                    edits.push((doc.whole_lines(&doc.tags[i].span), String::new()));
                }
            }
        }
        edits.push(doc.inertial_edit(doc.links[k], inertial, newline));
    }
    edits.sort_by_key(|(r, _)| r.start);
    for w in edits.windows(2) {
        if w[0].0.end > w[1].0.start {
            // Only possible if one link element encloses another, which URDF forbids.
            return Err(ReportError::Xml {
                line: line_of(original_text, w[1].0.start),
                message: "overlapping <link> elements".into(),
            });
        }
    }
    let mut out = original_text.to_string();
    for (range, text) in edits.into_iter().rev() {
        out.replace_range(range, &text);
    }
    Ok(out)
}

/// Sets `<dynamics damping friction>` of each named joint (viscous `Fv` and Coulomb
/// `Fc` friction, URDF's convention): an existing `<dynamics>` element is replaced,
/// otherwise one is added as the joint's first child. Every other byte is kept.
/// Errors: a joint not found or not unique (with its lines), a value negative or
/// not finite.
pub fn rewrite_urdf_dynamics<S: AsRef<str>>(
    original_text: &str,
    updates: &[(S, f64, f64)],
) -> Result<String, ReportError> {
    let doc = Document::scan(original_text)?;
    let newline = if original_text.contains("\r\n") { "\r\n" } else { "\n" };
    let root = doc.tags.iter().position(|t| t.parent.is_none());
    let mut edits: Vec<(std::ops::Range<usize>, String)> = Vec::new();
    for (k, (name, damping, friction)) in updates.iter().enumerate() {
        let name = name.as_ref();
        if updates[..k].iter().any(|(n, _, _)| n.as_ref() == name) {
            return Err(ReportError::Xml {
                line: 0,
                message: format!("joint `{name}` is given two <dynamics>"),
            });
        }
        if !(damping.is_finite() && friction.is_finite() && *damping >= 0.0 && *friction >= 0.0) {
            return Err(ReportError::InvalidDynamics {
                joint: name.into(),
                damping: *damping,
                friction: *friction,
            });
        }
        let found: Vec<usize> = (0..doc.tags.len())
            .filter(|&k| {
                let t = &doc.tags[k];
                t.parent == root && t.parent.is_some() && t.name == "joint" && t.attr("name") == Some(name)
            })
            .collect();
        let &[j] = &found[..] else {
            return Err(ReportError::JointNotFound {
                joint: name.into(),
                lines: found.iter().map(|&k| doc.tags[k].line).collect(),
            });
        };
        let element = format!("<dynamics damping=\"{damping:?}\" friction=\"{friction:?}\"/>");
        let joint = &doc.tags[j];
        if let Some(d) = doc.child(j, "dynamics") {
            edits.push((doc.tags[d].span.clone(), element));
            continue;
        }
        let joint_indent = doc.indent_at(joint.start.start).unwrap_or("");
        let child_indent = (0..doc.tags.len())
            .filter(|&k| doc.tags[k].parent == Some(j))
            .find_map(|k| doc.indent_at(doc.tags[k].start.start))
            .map_or_else(|| format!("{joint_indent}  "), str::to_string);
        if joint.self_closing {
            let open = doc.text[joint.start.clone()]
                .trim_end_matches('>')
                .trim_end_matches('/')
                .trim_end();
            edits.push((
                joint.start.clone(),
                format!("{open}>{newline}{child_indent}{element}{newline}{joint_indent}</joint>"),
            ));
        } else {
            let at = joint.start.end;
            edits.push((at..at, format!("{newline}{child_indent}{element}")));
        }
    }
    edits.sort_by_key(|(r, _)| r.start);
    let mut out = original_text.to_string();
    for (range, text) in edits.into_iter().rev() {
        out.replace_range(range, &text);
    }
    Ok(out)
}

/// The model builder's own test for a part of a body, so the file written is one
/// the model reads back.
fn check_inertial(link: &str, i: &Inertial) -> Result<(), ReportError> {
    check_physical(i).map_err(|kind| ReportError::InvalidInertial {
        link: link.into(),
        reason: kind.to_string(),
    })
}

fn line_of(text: &str, pos: usize) -> usize {
    1 + text.as_bytes()[..pos].iter().filter(|&&b| b == b'\n').count()
}

// The outline of the text comes from `dyngen_model::xml`, the URDF front end's own scan.

struct Document<'a> {
    text: &'a str,
    tags: Vec<Tag>,
    /// Tag indices of the `<link>` children of the root.
    links: Vec<usize>,
    /// `(parent link, child link, fixed)` of every `<joint>` child of the root.
    joints: Vec<(String, String, bool)>,
}

/// The moving body a link belongs to (`None`: the fixed base) and, when the link is
/// that body, the links merged into it.
struct Group<'a> {
    body: Option<&'a str>,
    merged: Vec<&'a str>,
}

impl<'a> Document<'a> {
    fn scan(text: &'a str) -> Result<Document<'a>, ReportError> {
        let tags = scan(text).map_err(|e| ReportError::Xml {
            line: e.line,
            message: e.message,
        })?;
        let root = tags.iter().position(|t| t.parent.is_none());
        let top = |name: &str| -> Vec<usize> {
            (0..tags.len())
                .filter(|&k| tags[k].parent == root && tags[k].parent.is_some() && tags[k].name == name)
                .collect()
        };
        let links = top("link");
        let child_link = |j: usize, what: &str| -> String {
            tags.iter()
                .find(|t| t.parent == Some(j) && t.name == what)
                .and_then(|t| t.attr("link"))
                .unwrap_or_default()
                .to_string()
        };
        let joints = top("joint")
            .into_iter()
            .map(|j| {
                (
                    child_link(j, "parent"),
                    child_link(j, "child"),
                    tags[j].attr("type") == Some("fixed"),
                )
            })
            .collect();
        Ok(Document {
            text,
            tags,
            links,
            joints,
        })
    }

    /// Index into `links` of the link called `name`, which must be unique.
    fn link(&self, name: &str) -> Result<usize, ReportError> {
        let found: Vec<usize> = (0..self.links.len())
            .filter(|&k| self.tags[self.links[k]].attr("name") == Some(name))
            .collect();
        match found[..] {
            [k] => Ok(k),
            [] => Err(ReportError::LinkNotFound { link: name.into() }),
            _ => Err(ReportError::DuplicateLink {
                link: name.into(),
                lines: found.iter().map(|&k| self.tags[self.links[k]].line).collect(),
            }),
        }
    }

    /// The link a link's body is rooted at: up through fixed joints until a moving
    /// joint (`Some`) or the root (`None`).
    fn body_of<'s>(&'s self, mut link: &'s str) -> Option<&'s str> {
        // A cycle would be rejected by the model builder; stop rather than loop.
        for _ in 0..=self.joints.len() {
            match self.joints.iter().find(|(_, c, _)| c == link) {
                None => return None,
                Some((_, _, false)) => return Some(link),
                Some((p, _, true)) => link = p,
            }
        }
        None
    }

    fn group<'s>(&'s self, link: &'s str) -> Group<'s> {
        let body = self.body_of(link);
        let merged = match body {
            Some(b) if b == link => self
                .links
                .iter()
                .filter_map(|&t| self.tags[t].attr("name"))
                .filter(|&n| n != link && self.body_of(n) == Some(link))
                .collect(),
            _ => Vec::new(),
        };
        Group { body, merged }
    }

    fn child(&self, parent: usize, name: &str) -> Option<usize> {
        (0..self.tags.len()).find(|&k| self.tags[k].parent == Some(parent) && self.tags[k].name == name)
    }

    /// The whitespace before byte `pos` on its line, if only whitespace precedes it.
    fn indent_at(&self, pos: usize) -> Option<&'a str> {
        let line_start = self.text[..pos].rfind('\n').map_or(0, |k| k + 1);
        let before = &self.text[line_start..pos];
        before.chars().all(|c| c == ' ' || c == '\t').then_some(before)
    }

    /// `span` widened to whole lines when the element sits alone on its lines, so
    /// removing it leaves no blank line.
    fn whole_lines(&self, span: &std::ops::Range<usize>) -> std::ops::Range<usize> {
        let rest = &self.text[span.end..];
        let trailing = rest.len() - rest.trim_start_matches([' ', '\t']).len();
        let after = &rest[trailing..];
        let eol = if after.starts_with("\r\n") {
            2
        } else {
            usize::from(after.starts_with('\n'))
        };
        match self.indent_at(span.start) {
            Some(indent) if eol > 0 => span.start - indent.len()..span.end + trailing + eol,
            _ => span.clone(),
        }
    }

    /// The edit that gives link tag `l` the inertial `i`.
    fn inertial_edit(&self, l: usize, i: &Inertial, newline: &str) -> (std::ops::Range<usize>, String) {
        let link = &self.tags[l];
        let link_indent = self.indent_at(link.start.start).unwrap_or("");
        // Indentation of the link's first child on a line of its own, else one unit more.
        let children: Vec<usize> = (0..self.tags.len())
            .filter(|&k| self.tags[k].parent == Some(l))
            .collect();
        // The document's unit: how far the link is indented inside <robot>.
        let root_indent = link.parent.and_then(|r| self.indent_at(self.tags[r].start.start));
        let doc_unit = root_indent
            .and_then(|r| link_indent.strip_prefix(r))
            .filter(|u| !u.is_empty())
            .unwrap_or("  ");
        let child_indent = children
            .iter()
            .find_map(|&k| self.indent_at(self.tags[k].start.start))
            .filter(|s| s.len() > link_indent.len())
            .map_or_else(|| format!("{link_indent}{doc_unit}"), str::to_string);
        let unit = child_indent
            .strip_prefix(link_indent)
            .filter(|u| !u.is_empty())
            .unwrap_or(doc_unit)
            .to_string();
        let element = |indent: &str| inertial_element(i, indent, &unit, newline);
        if let Some(k) = self.child(l, "inertial") {
            let t = &self.tags[k];
            let indent = self.indent_at(t.start.start).unwrap_or(&child_indent);
            return (t.span.clone(), element(indent));
        }
        if link.self_closing {
            let open = self.text[link.start.clone()]
                .trim_end_matches('>')
                .trim_end_matches('/')
                .trim_end();
            let text = format!(
                "{open}>{newline}{child_indent}{}{newline}{link_indent}</link>",
                element(&child_indent)
            );
            return (link.start.clone(), text);
        }
        let at = link.start.end;
        (at..at, format!("{newline}{child_indent}{}", element(&child_indent)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARM: &str = "<robot name=\"arm\">\n  <link name=\"base\"/>\n  <link name=\"a\"/>\n  <joint name=\"j1\" type=\"continuous\">\n    <parent link=\"base\"/>\n    <child link=\"a\"/>\n  </joint>\n  <link name=\"b\"/>\n  <joint name=\"j2\" type=\"continuous\">\n    <dynamics damping=\"0.1\"/>\n    <parent link=\"a\"/>\n    <child link=\"b\"/>\n  </joint>\n</robot>\n";

    #[test]
    fn dynamics_are_added_or_replaced_and_nothing_else_changes() {
        let out = rewrite_urdf_dynamics(ARM, &[("j1", 1.5, 2.0), ("j2", 0.25, 0.0)]).unwrap();
        let want = ARM
            .replace(
                "<joint name=\"j1\" type=\"continuous\">\n",
                "<joint name=\"j1\" type=\"continuous\">\n    <dynamics damping=\"1.5\" friction=\"2.0\"/>\n",
            )
            .replace(
                "<dynamics damping=\"0.1\"/>",
                "<dynamics damping=\"0.25\" friction=\"0.0\"/>",
            );
        assert_eq!(out, want);
    }

    #[test]
    fn bad_dynamics_updates_are_errors() {
        let e = rewrite_urdf_dynamics(ARM, &[("j3", 1.0, 1.0)]).unwrap_err();
        assert_eq!(e.to_string(), "no <joint name=\"j3\"> in the URDF");
        let e = rewrite_urdf_dynamics(ARM, &[("j1", -1.0, 1.0)]).unwrap_err();
        assert!(e.to_string().contains("both must be finite and ≥ 0"), "{e}");
        let e = rewrite_urdf_dynamics(ARM, &[("j1", 1.0, 1.0), ("j1", 2.0, 1.0)]).unwrap_err();
        assert!(e.to_string().contains("given two <dynamics>"), "{e}");
    }
}
