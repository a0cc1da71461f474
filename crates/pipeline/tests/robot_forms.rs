//! Every form of a robot description (RON axes, DH table, URDF) gives the same forward
//! kinematics: per fixture robot to 1e-9 m, and a DH table to poe's own DH model.

use lie::{SE3, SO3, Vector3};
use poe::{DhConvention, DhRow, JointKind, LocalPoe};
use robot::{ChainEnds, RobotDescription, UrdfDocument};

fn read(name: &str, base_link: Option<&str>) -> RobotDescription {
    let ends = ChainEnds { base_link: base_link.map(str::to_owned), tip_link: None };
    RobotDescription::read_with(&testkit::robot_path(name), &ends).unwrap_or_else(|e| panic!("{e}"))
}

/// Configurations spread over ±2.7 rad, the same for every form of a robot.
fn configurations(n: usize) -> Vec<Vec<f64>> {
    let mut qs = vec![vec![0.0; n]];
    for k in 1..8 {
        qs.push((0..n).map(|j| ((k * 7 + j * 3) as f64 * 0.61).sin() * 2.7).collect());
    }
    qs
}

/// How far two poses are apart: their origins and the ends of 1 m long axes, metres.
fn pose_difference_m(a: &SE3, b: &SE3) -> f64 {
    [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()]
        .iter()
        .map(|p| (a.transform_point(p) - b.transform_point(p)).norm())
        .fold(0.0, f64::max)
}

fn largest_difference_m(a: &LocalPoe, b: &LocalPoe) -> f64 {
    configurations(a.joint_count())
        .iter()
        .map(|q| pose_difference_m(&a.forward(q, 0).unwrap(), &b.forward(q, 0).unwrap()))
        .fold(0.0, f64::max)
}

#[test]
fn every_form_of_a_robot_has_the_same_forward_kinematics() {
    // The UR description's base_link is turned by pi from UR's (DH) base; its `base` link is not.
    let forms: [&[(&str, Option<&str>)]; 3] = [
        &[
            ("ur10.ron", None),
            ("ur10_dh.ron", None),
            ("ur10.urdf", Some("base")),
            ("ur10.urdf", Some("base_link_inertia")),
        ],
        &[("iiwa7.ron", None), ("iiwa7_dh.ron", None), ("iiwa7.urdf", None)],
        &[("irb4400.ron", None), ("irb4400_dh.ron", None), ("irb4400.urdf", None)],
    ];
    for robot in forms {
        let reference = read(robot[0].0, None).nominal_model().unwrap();
        for &(name, base) in &robot[1..] {
            let form = read(name, base);
            assert_eq!(form.joint_count(), reference.joint_count(), "{name}");
            let difference = largest_difference_m(&form.nominal_model().unwrap(), &reference);
            assert!(difference < 1e-9, "{name} from {base:?}: {difference:e} m");
        }
    }
}

#[test]
fn the_ur10_urdf_base_link_is_ros_aligned_half_a_turn_from_the_dh_base() {
    let dh_base = read("ur10.urdf", Some("base")).nominal_model().unwrap();
    let mut turned = dh_base.clone();
    turned.change_reference(SE3::new(SO3::exp(&(Vector3::z() * std::f64::consts::PI)), Vector3::zeros()));
    let ros = read("ur10.urdf", None).nominal_model().unwrap();
    assert!(largest_difference_m(&ros, &turned) < 1e-9);
}

#[test]
fn urdf_limits_and_the_default_chain_are_read() {
    let document = UrdfDocument::read(&testkit::robot_path("ur10.urdf")).unwrap();
    let chain = document.chain(&ChainEnds::default()).unwrap();
    assert_eq!((chain.base_link.as_str(), chain.tip_link.as_str(), chain.joint_count()), ("base_link", "tool0", 6));
    let robot = chain.description();
    assert_eq!(robot.name, "ur10");
    let limits = robot.limits();
    assert!((limits[2].1 - std::f64::consts::PI).abs() < 1e-12, "{limits:?}");
    assert!((limits[0].0 + std::f64::consts::TAU).abs() < 1e-12, "{limits:?}");
}

#[test]
fn a_dh_table_in_either_convention_moves_like_poes_dh_model() {
    let table = r#"Robot(
    name: "three",
    dh: (
        convention: CONVENTION,
        rows: [
            (kind: Revolute, a_m: 0.1, alpha_deg: 90.0, d_m: 0.3, theta_deg: 10.0, limits_deg: (-90.0, 90.0)),
            (kind: Prismatic, a_m: 0.4, alpha_rad: -0.3, d_m: 0.05, theta_rad: 0.2, limits_m: (0.0, 0.5)),
            (kind: Revolute, a_m: -0.2, alpha_deg: -45.0, d_m: 0.1, theta_deg: -30.0, limits_deg: (-170.0, 170.0)),
        ],
    ),
)"#;
    let rows = [
        DhRow { kind: JointKind::Revolute, a: 0.1, alpha: 90f64.to_radians(), d: 0.3, theta: 10f64.to_radians() },
        DhRow { kind: JointKind::Prismatic, a: 0.4, alpha: -0.3, d: 0.05, theta: 0.2 },
        DhRow { kind: JointKind::Revolute, a: -0.2, alpha: -45f64.to_radians(), d: 0.1, theta: -30f64.to_radians() },
    ];
    for (name, convention) in [("Standard", DhConvention::Standard), ("Modified", DhConvention::Modified)] {
        let robot = RobotDescription::parse(&table.replace("CONVENTION", name), "three.ron").unwrap();
        let expected = LocalPoe::from_dh(&rows, convention);
        let difference = largest_difference_m(&robot.nominal_model().unwrap(), &expected);
        assert!(difference < 1e-12, "{name}: {difference:e} m");
        assert_eq!(robot.limits()[1], (0.0, 0.5));
    }
}

#[test]
fn a_urdf_with_prismatic_continuous_and_tilted_axes_moves_like_its_joints() {
    // Each joint by hand: origin, then the motion about or along its (not unit) axis.
    let text = r#"<robot name="mixed">
  <link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="tip"/><link name="side"/>
  <joint name="j1" type="continuous"><parent link="a"/><child link="b"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.2 1.1"/><axis xyz="0 2 1"/></joint>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.5 0 0" rpy="0 0.4 0"/><axis xyz="1 0 0"/><limit lower="-0.1" upper="0.4" effort="1" velocity="1"/></joint>
  <joint name="fold" type="fixed"><parent link="c"/><child link="d"/><origin xyz="0 0.3 0" rpy="1 2 3"/></joint>
  <joint name="j3" type="revolute"><parent link="d"/><child link="tip"/>
    <origin xyz="0 0 0.2" rpy="-0.5 0 0.2"/><axis xyz="-1 1 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="aside" type="fixed"><parent link="a"/><child link="side"/></joint>
</robot>"#;
    let chain = UrdfDocument::parse(text, "mixed.urdf").unwrap().chain(&ChainEnds::default()).unwrap();
    assert_eq!(chain.tip_link, "tip");
    let robot = chain.description();
    assert_eq!(robot.limits()[0], (f64::NEG_INFINITY, f64::INFINITY));
    let model = robot.nominal_model().unwrap();
    let origin = |xyz: [f64; 3], rpy: [f64; 3]| SE3::new(SO3::from_rpy(rpy[0], rpy[1], rpy[2]), Vector3::from(xyz));
    let turn = |axis: [f64; 3], q: f64| SE3::new(SO3::exp(&(Vector3::from(axis).normalize() * q)), Vector3::zeros());
    let slide = |axis: [f64; 3], q: f64| SE3::from_translation(Vector3::from(axis).normalize() * q);
    for q in configurations(3) {
        let q = [q[0], 0.1 * q[1], q[2] / 3.0];
        let expected = origin([0.1, -0.2, 0.3], [0.3, -0.2, 1.1])
            * turn([0.0, 2.0, 1.0], q[0])
            * origin([0.5, 0.0, 0.0], [0.0, 0.4, 0.0])
            * slide([1.0, 0.0, 0.0], q[1])
            * origin([0.0, 0.3, 0.0], [1.0, 2.0, 3.0])
            * origin([0.0, 0.0, 0.2], [-0.5, 0.0, 0.2])
            * turn([-1.0, 1.0, 1.0], q[2]);
        let difference = pose_difference_m(&model.forward(&q, 0).unwrap(), &expected);
        assert!(difference < 1e-12, "{q:?}: {difference:e} m");
    }
}

#[test]
fn origin_angles_and_axes_of_any_size_give_the_motion_they_mean() {
    // rpy = 1e308 overflowed the exponential map into a NaN pose (found by `cargo xtask fuzz`).
    let arm = |rpy: &str, axis: &str| {
        let text = format!(
            r#"<robot name="r"><link name="a"/><link name="b"/><link name="tip"/>
  <joint name="j1" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0 0 0.3" rpy="{rpy}"/><axis xyz="{axis}"/></joint>
  <joint name="end" type="fixed"><parent link="b"/><child link="tip"/><origin xyz="0.4 0.1 0" rpy="0 0 0"/></joint>
</robot>"#
        );
        let chain = UrdfDocument::parse(&text, "r.urdf").unwrap().chain(&ChainEnds::default()).unwrap();
        chain.description().nominal_model().unwrap()
    };
    let huge = arm("1e308 -1e308 1e300", "0 0 1");
    let pose = huge.forward(&[0.7], 0).unwrap();
    assert!(pose.translation().iter().chain(pose.rotation().matrix().iter()).all(|v| v.is_finite()), "{pose:?}");
    let tau = std::f64::consts::TAU;
    let plain = arm(&format!("{} {} {}", 7.0 - tau, -8.0 + 2.0 * tau, 9.0 - tau), "0 0.6 0.8");
    let difference = largest_difference_m(&arm("7 -8 9", "0 0.6 0.8"), &plain);
    assert!(difference < 1e-12, "{difference:e} m");
    // An axis of any length is its direction: `0 -1e308 1` overflowed the norm into a NaN axis.
    let difference = largest_difference_m(&arm("0 0 0", "0 -1e308 1"), &arm("0 0 0", "0 -1 0"));
    assert!(difference < 1e-12, "{difference:e} m");
}
