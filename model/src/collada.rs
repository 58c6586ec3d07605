//! COLLADA's scene, placed as the format says before `mesh-loader` reads it.
//!
//! A COLLADA file places its geometries by a tree of nodes, each with its
//! own transforms, and gives every length in its `<unit>`. `mesh-loader`
//! composes a node's transform with its parents' in the reverse order (a
//! child's translation is turned by its own rotation instead of its
//! parent's), scales by the unit before the nodes' translations instead of
//! after them, drops any transform within 0.01 of the identity in every
//! entry (a part moved a few millimetres), applies the rest in single precision, and
//! also returns the geometries that no node places. Here the scene is
//! flattened first: each placed geometry gets one node directly under the
//! scene, with no transform, the document's unit becomes the metre, and
//! each geometry's whole transform (unit included) is returned beside the
//! document, for the caller to apply to the vertices the crate reads. Only
//! the scene's structure is rewritten; the geometries go through verbatim,
//! and the crate still parses them.
//!
//! The up axis (`<up_axis>`) is left alone, as ROS's tools leave it: a
//! URDF's mesh is read in the frame its numbers are written in.

use std::collections::HashMap;
use std::fmt::Write as _;

use nalgebra::{Matrix4, Rotation3, Unit, Vector3, Vector4};
use roxmltree::{Document, Node};

/// Nested `<node>`s and `<instance_node>`s followed at most: deeper is a
/// cycle of `<instance_node>` references.
const MAX_DEPTH: usize = 64;

/// A COLLADA document flattened (see the module's note).
pub(crate) struct FlatScene {
    /// The document: each placed geometry once, under a node of its own
    /// with no transform, in metres.
    pub text: String,
    /// Each geometry's id in `text` and the transform that places it,
    /// unit included, to apply to its vertices as `mesh-loader` reads them.
    pub placements: HashMap<String, Matrix4<f64>>,
}

/// The document with its scene flattened (see the module's note), or
/// `None` to leave it to `mesh-loader` as it is: text that is not XML, no
/// scene that places a geometry, or a transform this module does not read
/// (`<lookat>`, `<skew>`, a malformed number), which the crate then reads
/// or refuses by itself.
pub(crate) fn flatten_scene(text: &str) -> Option<FlatScene> {
    let doc = Document::parse(text).ok()?;
    let root = doc.root_element();
    let unit = child(root, "asset")
        .and_then(|asset| child(asset, "unit"))
        .and_then(|unit| unit.attribute("meter"))
        .map_or(Some(1.0), |meter| meter.trim().parse::<f64>().ok())?;
    let by_id: HashMap<&str, Node> = root
        .descendants()
        .filter_map(|n| Some((n.attribute("id")?, n)))
        .collect();
    let scene_url = child(root, "scene")
        .and_then(|scene| child(scene, "instance_visual_scene"))?
        .attribute("url")?;
    let scene = *by_id.get(scene_url.strip_prefix('#')?)?;
    if !(unit > 0.0 && unit.is_finite()) {
        return None;
    }
    let mut placed = Vec::new();
    let units = Matrix4::from_diagonal(&Vector4::new(unit, unit, unit, 1.0));
    place_children(scene, &units, &by_id, 0, &mut placed)?;
    if placed.is_empty() {
        return None;
    }
    let mut geometries = String::new();
    let mut nodes = String::new();
    let mut placements = HashMap::new();
    let mut instances: HashMap<&str, usize> = HashMap::new();
    for (k, (url, transform)) in placed.iter().enumerate() {
        let id = url.strip_prefix('#')?;
        let geometry = *by_id.get(id)?;
        if !geometry.has_tag_name("geometry") {
            return None;
        }
        // A geometry placed twice is copied under a new id: the crate keeps
        // one transform per geometry.
        let count = instances.entry(id).or_insert(0);
        let text = &doc.input_text()[geometry.range()];
        let name = if *count == 0 {
            geometries.push_str(text);
            id.to_owned()
        } else {
            let copy = format!("{id}-gjkd-copy-{count}");
            geometries.push_str(&renamed(text, id, &copy)?);
            copy
        };
        *count += 1;
        let _ = write!(
            nodes,
            r##"<node id="gjkd-node-{k}"><instance_geometry url="#{name}"/></node>"##
        );
        placements.insert(name, *transform);
    }
    let namespace = root.tag_name().namespace().unwrap_or_default();
    let version = root.attribute("version").unwrap_or("1.4.1");
    let text = format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="{namespace}" version="{version}">
<asset><unit name="meter" meter="1"/></asset>
<library_geometries>{geometries}</library_geometries>
<library_visual_scenes><visual_scene id="gjkd-scene">{nodes}</visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#gjkd-scene"/></scene>
</COLLADA>
"##
    );
    Some(FlatScene { text, placements })
}

/// The first child element of `node` named `name`.
fn child<'a, 'input>(node: Node<'a, 'input>, name: &str) -> Option<Node<'a, 'input>> {
    node.children().find(|c| c.has_tag_name(name))
}

/// Adds to `placed` every geometry that `node`'s children place, with its
/// transform: `parent`, then each child node's own. `None` on a transform
/// not read here or a cycle.
fn place_children<'a>(
    node: Node<'a, '_>,
    parent: &Matrix4<f64>,
    by_id: &HashMap<&str, Node<'a, '_>>,
    depth: usize,
    placed: &mut Vec<(&'a str, Matrix4<f64>)>,
) -> Option<()> {
    if depth > MAX_DEPTH {
        return None;
    }
    for c in node.children().filter(Node::is_element) {
        match c.tag_name().name() {
            "instance_geometry" => placed.push((c.attribute("url")?, *parent)),
            "node" => place_node(c, parent, by_id, depth, placed)?,
            "instance_node" => {
                let target = *by_id.get(c.attribute("url")?.strip_prefix('#')?)?;
                place_node(target, parent, by_id, depth, placed)?;
            }
            _ => {}
        }
    }
    Some(())
}

/// [`place_children`] for the children of the `<node>` `node`, under
/// `parent` composed with `node`'s own transforms in document order.
fn place_node<'a>(
    node: Node<'a, '_>,
    parent: &Matrix4<f64>,
    by_id: &HashMap<&str, Node<'a, '_>>,
    depth: usize,
    placed: &mut Vec<(&'a str, Matrix4<f64>)>,
) -> Option<()> {
    let mut transform = *parent;
    for c in node.children().filter(Node::is_element) {
        let step = match c.tag_name().name() {
            "matrix" => {
                let m: [f64; 16] = numbers(c)?;
                Matrix4::from_row_slice(&m)
            }
            "translate" => Matrix4::new_translation(&Vector3::from(numbers::<3>(c)?)),
            "scale" => Matrix4::new_nonuniform_scaling(&Vector3::from(numbers::<3>(c)?)),
            "rotate" => {
                let [x, y, z, degrees] = numbers(c)?;
                let axis = Unit::try_new(Vector3::new(x, y, z), 0.0)?;
                Rotation3::from_axis_angle(&axis, degrees.to_radians()).to_homogeneous()
            }
            "lookat" | "skew" => return None,
            _ => continue,
        };
        transform *= step;
    }
    place_children(node, &transform, by_id, depth + 1, placed)
}

/// The `N` numbers of an element's text, all finite.
fn numbers<const N: usize>(node: Node) -> Option<[f64; N]> {
    let mut out = [0.0; N];
    let mut words = node.text()?.split_ascii_whitespace();
    for x in &mut out {
        *x = words.next()?.parse().ok().filter(|x: &f64| x.is_finite())?;
    }
    words.next().is_none().then_some(out)
}

/// `text`, a `<geometry>` element, with its id `id` (in its start tag)
/// changed to `new`.
fn renamed(text: &str, id: &str, new: &str) -> Option<String> {
    let end = text.find('>')?;
    let (tag, rest) = text.split_at(end);
    let tag = ["\"", "'"].iter().find_map(|q| {
        let old = format!("id={q}{id}{q}");
        tag.contains(&old)
            .then(|| tag.replacen(&old, &format!("id={q}{new}{q}"), 1))
    })?;
    Some(tag + rest)
}
