//! The pieces of URDF text both exports write: escaped attributes, origins that round-trip, fixed
//! joints, and what a writer produced.

use lie::SE3;
use std::fmt::Write;

/// What a writer produced.
pub(crate) struct Written {
    pub text: String,
    pub robot: String,
    pub base_link: String,
    pub tracker_link: String,
    pub tool_links: Vec<String>,
    /// The movable joints' names, base first.
    pub joint_names: Vec<String>,
}

/// Text for an XML attribute value.
pub(crate) fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;").replace('>', "&gt;")
}

/// `<origin xyz=".." rpy=".."/>` of a transform, every number written to round-trip exactly.
pub(crate) fn origin_element(pose: &SE3) -> String {
    let t = pose.translation();
    let [r, p, y] = pose.rotation().to_rpy();
    format!("<origin xyz=\"{:?} {:?} {:?}\" rpy=\"{r:?} {p:?} {y:?}\"/>", t.x, t.y, t.z)
}

/// A fixed joint from `parent` to a new link `child`.
pub(crate) fn fixed_joint(text: &mut String, indent: &str, parent: &str, child: &str, origin: &SE3) {
    let _ = writeln!(
        text,
        "{indent}<joint name=\"{p}-{c}\" type=\"fixed\">\n{indent}  <parent link=\"{p}\"/>\n{indent}  <child link=\"{c}\"/>\n{indent}  {}\n{indent}</joint>",
        origin_element(origin),
        p = escape(parent),
        c = escape(child)
    );
}
