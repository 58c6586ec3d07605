//! URDF text parsed into `urdf-rs`'s [`urdf_rs::Robot`], with the elements
//! gjkd never reads taken out first.
//!
//! gjkd needs a URDF's links, joints and collision elements only. Real
//! descriptions often hold visual and inertial data that `urdf-rs` refuses
//! though the URDF specification's readers accept it (a `<texture/>` without
//! a file name in a visual's material, for one): such a robot should load
//! all the same, since none of it changes a link's pose or shape. So a
//! link's `<visual>` and `<inertial>` elements and the robot's own
//! `<material>` elements are cut out of the text, by the byte ranges a real
//! XML parser gives, before `urdf-rs` reads it; so are the parts ROS's
//! parser never reads and `urdf-rs` may refuse: a collision geometry's
//! elements after its first, a fixed or floating joint's `<axis>`. Text that is not
//! well-formed XML goes to `urdf-rs` as it is, to get its own error.
//! Namespace prefixes used undeclared (as ROS's parser allows) are renamed
//! first (see `xml_prefixes`).

use std::ops::Range;

use crate::kinematics_error::KinematicsError;
use crate::xml_prefixes::rename_unbound_prefixes;

/// Parses URDF text, the elements gjkd never reads removed.
///
/// # Errors
/// [`KinematicsError::Malformed`] with `urdf-rs`'s (or the XML parser's)
/// message.
pub(crate) fn parse_urdf(text: &str) -> Result<urdf_rs::Robot, KinematicsError> {
    let text = rename_unbound_prefixes(text);
    let text = text.as_ref();
    let stripped = without_unused_elements(text);
    urdf_rs::read_from_string(stripped.as_deref().unwrap_or(text))
        .map_err(|e| KinematicsError::Malformed(e.to_string()))
}

/// `node`'s child elements named `name`.
fn elements<'a, 'input>(
    node: roxmltree::Node<'a, 'input>,
    name: &'static str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'input>> {
    node.children()
        .filter(move |n| n.is_element() && n.tag_name().name() == name)
}

/// The text without the unused elements, or `None` when there are none or
/// the text is not well-formed XML (then `urdf-rs` reports on it as it is).
fn without_unused_elements(text: &str) -> Option<String> {
    let doc = roxmltree::Document::parse(text).ok()?;
    let root = doc.root_element();
    let mut cut: Vec<Range<usize>> = Vec::new();
    for child in root.children().filter(roxmltree::Node::is_element) {
        match child.tag_name().name() {
            "material" => cut.push(child.range()),
            "link" => {
                for element in child.children().filter(roxmltree::Node::is_element) {
                    match element.tag_name().name() {
                        "visual" | "inertial" => cut.push(element.range()),
                        // ROS reads a geometry's first element only: what
                        // follows (an `<origin>` put there by mistake) is
                        // no part of it.
                        "collision" => {
                            for geometry in elements(element, "geometry") {
                                cut.extend(
                                    geometry
                                        .children()
                                        .filter(roxmltree::Node::is_element)
                                        .skip(1)
                                        .map(|n| n.range()),
                                );
                            }
                        }
                        _ => {}
                    }
                }
            }
            // ROS reads no axis of a fixed or floating joint, so a
            // malformed one there does not matter.
            "joint" if matches!(child.attribute("type"), Some("fixed" | "floating")) => {
                cut.extend(elements(child, "axis").map(|n| n.range()));
            }
            _ => {}
        }
    }
    if cut.is_empty() {
        return None;
    }
    cut.sort_by_key(|r| r.start);
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for range in cut {
        out.push_str(&text[at..range.start]);
        at = range.end;
    }
    out.push_str(&text[at..]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visuals_inertials_and_materials_are_cut_and_the_rest_kept() {
        let text = r#"<?xml version="1.0"?>
<robot name="r">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/><texture/></material>
  <link name="a">
    <inertial><mass value="1"/></inertial>
    <visual><geometry><box size="1 1 1"/></geometry>
      <material name="m"><texture/></material></visual>
    <collision><geometry><sphere radius="0.5"/></geometry></collision>
  </link>
</robot>"#;
        // urdf-rs alone refuses the file-less texture.
        assert!(urdf_rs::read_from_string(text).is_err());
        let stripped = without_unused_elements(text).unwrap();
        for gone in ["material", "visual", "inertial", "texture"] {
            assert!(!stripped.contains(gone), "{gone} left in {stripped}");
        }
        let robot = parse_urdf(text).unwrap();
        assert_eq!(robot.links.len(), 1);
        assert_eq!(robot.links[0].collision.len(), 1);
        assert!(robot.links[0].visual.is_empty());
    }

    #[test]
    fn what_ros_never_reads_is_cut_and_the_robot_loads() {
        // A description in the wild: an origin inside a geometry after its
        // shape, a fixed joint's axis with a misspelt attribute.
        let text = r#"<robot name="r">
  <link name="a"><collision><origin xyz="0 0 1"/>
    <geometry name="g"><box size="1 2 3"/><origin xyz="5 0 0"/></geometry>
  </collision></link>
  <link name="b"/>
  <joint name="f" type="fixed"><parent link="a"/><child link="b"/><axis xzy="0 0 1"/></joint>
  <link name="c"/>
  <joint name="m" type="revolute"><parent link="a"/><child link="c"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;
        assert!(urdf_rs::read_from_string(text).is_err());
        let robot = parse_urdf(text).unwrap();
        let collision = &robot.links[0].collision[0];
        assert_eq!(collision.origin.xyz.0, [0.0, 0.0, 1.0]);
        assert!(matches!(
            collision.geometry,
            urdf_rs::Geometry::Box { ref size } if size.0 == [1.0, 2.0, 3.0]
        ));
        assert_eq!(robot.joints[1].axis.xyz.0, [0.0, 1.0, 0.0]);
    }

    #[test]
    fn text_without_unused_elements_and_malformed_text_pass_as_they_are() {
        assert_eq!(
            without_unused_elements(r#"<robot name="r"><link name="a"/></robot>"#),
            None
        );
        assert_eq!(without_unused_elements("<robot name='r'><link"), None);
        assert!(matches!(
            parse_urdf("<robot name='r'><link"),
            Err(KinematicsError::Malformed(_))
        ));
    }
}
