//! Every URDF the robot reader refuses, each at the file, line and column at fault.

use robot::ErrorKind;
use robot::{ChainEnds, RobotDescription, UrdfDocument};

/// A two-joint arm; each test breaks one thing.
const ARM: &str = r#"<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="upper"/>
  <link name="tip"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/>
    <child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/>
    <child link="tip"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/>
  </joint>
</robot>
"#;

fn ends(base: Option<&str>, tip: Option<&str>) -> ChainEnds {
    ChainEnds { base_link: base.map(str::to_owned), tip_link: tip.map(str::to_owned) }
}

/// The refusal of `text` with `ends`: line, column and message, checked to name the file first.
fn refuse_with(text: &str, ends: &ChainEnds) -> (usize, usize, String) {
    let result = UrdfDocument::parse(text, "arm.urdf").and_then(|d| d.chain(ends));
    match result {
        Err(e) if matches!(e.kind::<ErrorKind>(), Some(ErrorKind::UrdfFormat { .. })) => {
            let shown = e.to_string();
            let (Some((line, column)), Some(ErrorKind::UrdfFormat { message })) = (e.position(), e.kind::<ErrorKind>())
            else {
                unreachable!()
            };
            assert_eq!(shown, format!("arm.urdf:{line}:{column}: {message}"));
            (line as usize, column, message.clone())
        }
        other => panic!("expected a URDF error, got {other:?}"),
    }
}

fn refuse(text: &str) -> (usize, usize, String) {
    refuse_with(text, &ChainEnds::default())
}

fn assert_refused(text: &str, position: (usize, usize), words: &str) {
    let (line, column, message) = refuse(text);
    assert_eq!((line, column), position, "{message}");
    assert!(message.contains(words), "{message}");
}

#[test]
fn the_arm_itself_reads() {
    let chain = UrdfDocument::parse(ARM, "arm.urdf").unwrap().chain(&ChainEnds::default()).unwrap();
    assert_eq!((chain.base_link.as_str(), chain.tip_link.as_str(), chain.joint_count()), ("base", "tip", 2));
}

#[test]
fn xml_that_is_not_well_formed_is_refused_where_it_breaks() {
    assert_refused(&ARM.replace("<child link=\"tip\"/>", "<child link=\"tip\">"), (19, 3), "does not match <child>");
    assert_refused(&ARM.replace("<axis xyz=\"0 0 1\"/>", "<axis xyz=0/>"), (10, 15), "not quoted");
}

#[test]
fn bytes_that_are_not_utf8_are_refused_at_their_line_and_column() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("arm.urdf");
    let mut bytes = ARM.as_bytes().to_vec();
    let at = ARM.find("<link name=\"tip\"/>").unwrap() + "<link name=\"".len();
    bytes.insert(at, 0xff);
    std::fs::write(&path, bytes).unwrap();
    let message = RobotDescription::read(&path).unwrap_err().to_string();
    assert_eq!(message, format!("{}:5:15: the text is not UTF-8", path.display()));
}

#[test]
fn a_file_nested_deeper_than_any_urdf_is_refused_not_a_stack_overflow() {
    // 200,000 nested elements aborted the process on a stack overflow (found by `cargo xtask fuzz`).
    let deep = format!("<robot name=\"r\">\n{}{}</robot>\n", "<a>".repeat(200_000), "</a>".repeat(200_000));
    let (line, column, message) = refuse(&deep);
    assert_eq!((line, column), (2, 1 + 3 * 255), "{message}");
    assert!(message.contains("nested 257 elements deep"), "{message}");
}

#[test]
fn an_error_only_the_xml_parser_finds_is_placed_where_it_says() {
    // An unknown entity: the outline keeps it as text, the XML parser refuses it with a position
    // that the message used to drop for the file's first line (found by `cargo xtask fuzz`).
    let text = ARM.replace("<link name=\"tip\"/>", "<link name=\"t&foo;ip\"/>");
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 5, "{message}");
    assert!(message.contains("invalid entity"), "{message}");
}

#[test]
fn a_xacro_file_or_another_root_is_refused() {
    assert_refused(
        &ARM.replace("<robot name=\"arm\">", "<robot name=\"arm\" xmlns:xacro=\"http://ros.org/wiki/xacro\">"),
        (2, 1),
        "expand it first",
    );
    assert_refused("<?xml version=\"1.0\"?>\n<sdf version=\"1.6\"/>", (2, 1), "the root element is <sdf>");
}

#[test]
fn a_value_that_is_not_three_numbers_is_refused_at_the_value() {
    assert_refused(
        &ARM.replace("xyz=\"0.4 0 0\"", "xyz=\"0.4 0 x\""),
        (16, 18),
        "joint 'elbow': <origin xyz=\"0.4 0 x\"> must be three numbers",
    );
}

#[test]
fn duplicate_or_undefined_links_and_a_link_with_two_parents_are_refused() {
    assert_refused(
        &ARM.replace("<link name=\"tip\"/>", "<link name=\"upper\"/>"),
        (5, 3),
        "a second link named 'upper'",
    );
    assert_refused(
        &ARM.replace("<child link=\"tip\"/>", "<child link=\"hand\"/>"),
        (13, 3),
        "names link 'hand', which is not defined",
    );
    assert_refused(
        &ARM.replace("<child link=\"tip\"/>", "<child link=\"upper\"/>"),
        (13, 3),
        "is the child of joints 'shoulder' and 'elbow'",
    );
}

#[test]
fn joints_that_cannot_be_calibrated_are_refused_on_the_chain() {
    for kind in ["floating", "planar"] {
        let text = ARM.replace("name=\"elbow\" type=\"revolute\"", &format!("name=\"elbow\" type=\"{kind}\""));
        assert_refused(&text, (13, 3), &format!("joint 'elbow': {kind} joints cannot be calibrated"));
    }
    let mimic = ARM.replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 1 0\"/>\n    <mimic joint=\"shoulder\"/>");
    // A mimic joint folds into the joint it follows only where their motions add (urdf_mimic.rs).
    assert_refused(&mimic, (18, 5), "mimic joint 'elbow': its axis is at 90.0000 deg to the axis of joint 'shoulder'");
    assert_refused(&ARM.replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 0 0\"/>"), (13, 3), "the axis is zero");
    assert_refused(&ARM.replace("xyz=\"0.4 0 0\"", "xyz=\"0.4 inf 0\""), (13, 3), "must be finite");
}

#[test]
fn a_floating_joint_off_the_chain_is_left_alone() {
    let text = ARM.replace(
        "</robot>",
        "  <link name=\"camera\"/>\n  <joint name=\"loose\" type=\"floating\"><parent link=\"base\"/><child link=\"camera\"/></joint>\n</robot>",
    );
    let chain = UrdfDocument::parse(&text, "arm.urdf").unwrap().chain(&ChainEnds::default()).unwrap();
    assert_eq!(chain.tip_link, "tip");
}

#[test]
fn missing_or_reversed_limits_are_refused() {
    let text = ARM.replace("    <limit lower=\"-2\" upper=\"2\" effort=\"10\" velocity=\"1\"/>\n", "");
    assert_refused(&text, (13, 3), "a <limit lower=.. upper=..> is required");
    let text = ARM.replace("lower=\"-2\" upper=\"2\"", "lower=\"2\" upper=\"-2\"");
    assert_refused(&text, (13, 3), "must be finite and increasing");
    let text = ARM.replace("lower=\"-2\" upper=\"2\"", "lower=\"-1e308\" upper=\"2\"");
    assert_refused(&text, (13, 3), "limits lower -1e308 upper 2e0 reach beyond ±1e6 rad");
}

#[test]
fn an_ambiguous_tip_or_base_is_refused_until_chosen() {
    let two_tips = ARM.replace(
        "</robot>",
        "  <link name=\"tip2\"/>\n  <joint name=\"elbow2\" type=\"continuous\"><parent link=\"upper\"/><child link=\"tip2\"/></joint>\n</robot>",
    );
    let (line, column, message) = refuse(&two_tips);
    assert_eq!((line, column), (3, 3), "{message}");
    assert!(message.contains("ambiguous chain: leaves tip, tip2") && message.contains("--tip-link"), "{message}");
    let chain = UrdfDocument::parse(&two_tips, "arm.urdf").unwrap().chain(&ends(None, Some("tip2"))).unwrap();
    assert_eq!(chain.steps.last().map(|s| s.joint.as_str()), Some("elbow2"));

    let two_roots = ARM.replace("<link name=\"tip\"/>", "<link name=\"tip\"/>\n  <link name=\"table\"/>");
    assert_refused(&two_roots, (6, 3), "several root links (base, table): choose the base with --base-link");
}

#[test]
fn a_loop_without_a_root_is_refused() {
    let text = ARM.replace(
        "</robot>",
        "  <joint name=\"back\" type=\"fixed\"><parent link=\"tip\"/><child link=\"base\"/></joint>\n</robot>",
    );
    assert_refused(&text, (2, 1), "no root link");
}

#[test]
fn chain_ends_that_do_not_make_a_chain_are_refused() {
    let (line, column, message) = refuse_with(ARM, &ends(Some("hand"), None));
    assert_eq!((line, column), (2, 1), "{message}");
    assert!(message.contains("--base-link: no link named 'hand' (links: base, upper, tip)"), "{message}");
    let (_, _, message) = refuse_with(ARM, &ends(None, Some("hand")));
    assert!(message.starts_with("--tip-link: no link named 'hand'"), "{message}");
    let (line, column, message) = refuse_with(ARM, &ends(Some("tip"), Some("base")));
    assert_eq!((line, column), (13, 3), "{message}");
    assert!(message.contains("runs through this movable joint from child to parent"), "{message}");
    let (line, column, message) = refuse_with(ARM, &ends(Some("upper"), Some("upper")));
    assert_eq!((line, column), (4, 3), "{message}");
    assert!(message.contains("no movable joint between"), "{message}");
    let apart = ARM.replace("<link name=\"tip\"/>", "<link name=\"tip\"/>\n  <link name=\"table\"/>");
    let (line, _, message) = refuse_with(&apart, &ends(Some("base"), Some("table")));
    assert_eq!(line, 6, "{message}");
    assert!(message.contains("no chain joins base link 'base' and tip link 'table'"), "{message}");
}

#[test]
fn a_ron_file_refuses_chain_ends() {
    let path = testkit::robot_path("ur10.ron");
    let error = RobotDescription::read_with(&path, &ends(Some("base"), None)).unwrap_err().to_string();
    assert!(
        error.ends_with(
            "ur10.ron:1:1: --base-link and --tip-link choose the chain of a URDF (.urdf), not of a RON robot file"
        ),
        "{error}"
    );
}
