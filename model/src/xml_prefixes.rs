//! Namespace prefixes that a robot description uses without declaring them,
//! renamed so that a namespace-aware XML parser reads the text as ROS's does.
//!
//! ROS reads URDF and SRDF with TinyXML, which knows no namespaces: a tag
//! such as `<sensor:camera>` inside a `<gazebo>` element is a name with a
//! colon in it. Real descriptions rely on that (Fetch's, for one, names its
//! Gazebo sensors so with no `xmlns:sensor` anywhere), while `roxmltree`
//! and `urdf-rs`'s parser refuse a prefix no `xmlns:` declaration binds.
//! So before parsing, the colon of every element or attribute name whose
//! prefix is unbound where it stands is replaced by `_`: the text keeps its
//! length and byte offsets, bound prefixes (`xacro:` under an
//! `xmlns:xacro`) are left alone, and none of the renamed elements is one
//! gjkd reads (URDF's and SRDF's own elements have no prefix).

use std::borrow::Cow;

/// What the scan skips whole, by its start and end: comments, CDATA
/// sections, processing instructions and declarations (the order matters:
/// `<!` last).
const SKIPPED: [(&[u8], &[u8]); 4] = [
    (b"<!--", b"-->"),
    (b"<![CDATA[", b"]]>"),
    (b"<?", b"?>"),
    (b"<!", b">"),
];

/// `text` with the colon of every unbound prefix in an element or attribute
/// name replaced by `_` (see the module's note), or `text` itself when
/// there is none. Text that is not well-formed XML is scanned as far as it
/// goes; the parser that reads the result then reports on it.
pub(crate) fn rename_unbound_prefixes(text: &str) -> Cow<'_, str> {
    let colons = unbound_prefix_colons(text.as_bytes());
    if colons.is_empty() {
        return Cow::Borrowed(text);
    }
    let mut bytes = text.as_bytes().to_vec();
    for at in colons {
        bytes[at] = b'_';
    }
    // An ASCII byte replaced by another keeps the text UTF-8.
    Cow::Owned(String::from_utf8(bytes).expect("ASCII for ASCII keeps UTF-8"))
}

/// The offsets of the colons to replace: those of element and attribute
/// names whose prefix no `xmlns:` on the element or an enclosing one binds.
/// Comments, CDATA sections, processing instructions and declarations are
/// skipped; so are attribute values.
fn unbound_prefix_colons(b: &[u8]) -> Vec<usize> {
    let mut colons = Vec::new();
    // The prefixes each open element declares, outermost first.
    let mut scopes: Vec<Vec<&[u8]>> = Vec::new();
    let mut i = 0;
    while let Some(offset) = b[i..].iter().position(|&c| c == b'<') {
        let at = i + offset;
        let rest = &b[at..];
        if let Some((_, end)) = SKIPPED.iter().find(|(start, _)| rest.starts_with(start)) {
            i = find(b, at, end).map_or(b.len(), |e| e + end.len());
            continue;
        }
        let closing = rest.starts_with(b"</");
        let mut j = at + if closing { 2 } else { 1 };
        let name = j;
        j = name_end(b, j);
        let name = (name, &b[name..j]);
        if closing {
            check_prefix(name, &scopes, &mut colons);
            scopes.pop();
            i = find(b, j, b">").map_or(b.len(), |e| e + 1);
            continue;
        }
        let mut declared = Vec::new();
        let mut attributes = Vec::new();
        let mut self_closing = false;
        loop {
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            match b.get(j) {
                None => break,
                Some(b'>') => {
                    j += 1;
                    break;
                }
                Some(b'/') => {
                    self_closing = true;
                    j = find(b, j, b">").map_or(b.len(), |e| e + 1);
                    break;
                }
                Some(_) => {}
            }
            let start = j;
            j = name_end(b, j).max(j + 1);
            let attribute = &b[start..j.min(b.len())];
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if b.get(j) == Some(&b'=') {
                j += 1;
                while j < b.len() && b[j].is_ascii_whitespace() {
                    j += 1;
                }
                if let Some(&quote @ (b'"' | b'\'')) = b.get(j) {
                    j = find(b, j + 1, &[quote]).map_or(b.len(), |e| e + 1);
                }
            }
            match attribute.strip_prefix(b"xmlns:") {
                Some(prefix) => declared.push(prefix),
                None => attributes.push((start, attribute)),
            }
        }
        scopes.push(declared);
        check_prefix(name, &scopes, &mut colons);
        for attribute in attributes {
            check_prefix(attribute, &scopes, &mut colons);
        }
        if self_closing {
            scopes.pop();
        }
        i = j.min(b.len());
    }
    colons
}

/// Where the name starting at `j` ends: at white space, `=`, `>` or `/`.
fn name_end(b: &[u8], mut j: usize) -> usize {
    while j < b.len() && !b[j].is_ascii_whitespace() && !matches!(b[j], b'=' | b'>' | b'/') {
        j += 1;
    }
    j
}

/// The offset of the first `needle` in `b` from `from` on.
fn find(b: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    b.get(from..)?
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|p| from + p)
}

/// Records the colon of the name `(start, name)` if its prefix is unbound
/// in `scopes` (`xml` and `xmlns` are always bound).
fn check_prefix((start, name): (usize, &[u8]), scopes: &[Vec<&[u8]>], colons: &mut Vec<usize>) {
    let Some(colon) = name.iter().position(|&c| c == b':') else {
        return;
    };
    let prefix = &name[..colon];
    let bound = prefix == b"xml"
        || prefix == b"xmlns"
        || scopes.iter().flatten().any(|&declared| declared == prefix);
    if !bound {
        colons.push(start + colon);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unbound_prefixes_are_renamed_and_bound_ones_kept() {
        let text = r#"<?xml version="1.0"?>
<!-- <note:a> in a comment stays -->
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="p" value="a:b"/>
  <gazebo reference="l"><sensor:camera name="rgb" cam:fov='50'><x/></sensor:camera></gazebo>
  <plugin xmlns:local="urn:x"><local:y/></plugin>
  <local:z/>
  <![CDATA[ <cdata:kept> ]]>
</robot>"#;
        let renamed = rename_unbound_prefixes(text);
        let want = text
            .replace("<sensor:camera", "<sensor_camera")
            .replace("</sensor:camera", "</sensor_camera")
            .replace("cam:fov", "cam_fov")
            .replace("<local:z", "<local_z");
        assert_eq!(renamed, want);
        assert_eq!(renamed.len(), text.len());
        assert!(roxmltree::Document::parse(text).is_err());
        assert!(roxmltree::Document::parse(&renamed).is_ok());
    }

    #[test]
    fn text_with_every_prefix_bound_is_borrowed_and_broken_text_scanned_safely() {
        let text = r#"<robot name="r" xmlns:a="urn:a"><a:b/></robot>"#;
        assert!(matches!(rename_unbound_prefixes(text), Cow::Borrowed(_)));
        for broken in [
            "<",
            "<a:",
            "<a:b c:d",
            "<a:b c:d='",
            "</",
            "<!--",
            "<x y=\"1\" /",
        ] {
            let renamed = rename_unbound_prefixes(broken);
            assert_eq!(renamed.len(), broken.len(), "{broken}");
        }
        assert_eq!(rename_unbound_prefixes("<a:b c:d='"), "<a_b c_d='");
    }
}
