//! A URDF's `<inertial>` masses as the load model's data: the same `RobotDynamics` as
//! the equivalent RON file, links on fixed joints and mimic stages folded into the joint they ride
//! on, no mass model where a joint's body states none, and bad values refused at their element.

use errors::ErrorKind;
use lie::{SE3, SO3, Vector3};
use robot::{ChainEnds, RobotDescription, UrdfDocument};

/// `iiwa7.urdf`'s link origins at the zero configuration (the arm straight up, frames parallel to
/// the base), as its comment gives them.
const IIWA_LINK_HEIGHTS: [f64; 7] = [0.1575, 0.34, 0.5445, 0.74, 0.9245, 1.14, 1.221];

/// A sensor hung from `link_7` by a fixed joint turned about all three axes, its mass 0.1219 kg of
/// the 0.4219 kg that `iiwa7.ron` gives link 7.
const SENSOR_ORIGIN: ([f64; 3], [f64; 3]) = ([0.01, 0.02, 0.03], [0.3, -0.2, 1.1]);
const SENSOR_MASS_KG: f64 = 0.1219;

fn inertial(mass_kg: f64, com_in_link: Vector3) -> String {
    format!(
        "<inertial><origin xyz=\"{:?} {:?} {:?}\" rpy=\"0.1 0.2 0.3\"/><mass value=\"{mass_kg:?}\"/>\
         <inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>",
        com_in_link.x, com_in_link.y, com_in_link.z
    )
}

/// `iiwa7.urdf` with the masses and centres of `iiwa7.ron` written into its links: each centre
/// in its link's frame, link 7's split between `link_7` and a sensor whose frame is turned, placed
/// so that their combined centre is the RON file's.
fn iiwa_with_inertials(ron: &loadsim::RobotDynamics) -> String {
    let mut text = std::fs::read_to_string(testkit::robot_path("iiwa7.urdf")).unwrap();
    let (xyz, rpy) = SENSOR_ORIGIN;
    let sensor_origin = SE3::new(SO3::from_rpy(rpy[0], rpy[1], rpy[2]), Vector3::from(xyz));
    for (k, (link, height)) in ron.links.iter().zip(IIWA_LINK_HEIGHTS).enumerate() {
        let base_from_link = SE3::from_translation(Vector3::new(0.0, 0.0, height));
        let com = Vector3::from(link.com_m);
        let element = if k == 6 {
            let sensor_com = com + Vector3::new(0.05, -0.02, 0.01);
            let own_mass = link.mass_kg - SENSOR_MASS_KG;
            let own_com = (com * link.mass_kg - sensor_com * SENSOR_MASS_KG) / own_mass;
            let base_from_sensor = base_from_link * sensor_origin;
            let sensor = inertial(SENSOR_MASS_KG, base_from_sensor.inverse().transform_point(&sensor_com));
            text = text.replace(
                "</robot>",
                &format!(
                    "  <link name=\"sensor\">{sensor}</link>\n  <joint name=\"link_7-sensor\" type=\"fixed\">\
                     <parent link=\"link_7\"/><child link=\"sensor\"/>\
                     <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/></joint>\n</robot>",
                    xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]
                ),
            );
            inertial(own_mass, base_from_link.inverse().transform_point(&own_com))
        } else {
            inertial(link.mass_kg, base_from_link.inverse().transform_point(&com))
        };
        let name = format!("link_{}", k + 1);
        text = text.replace(&format!("<link name=\"{name}\"/>"), &format!("<link name=\"{name}\">{element}</link>"));
    }
    text
}

#[test]
fn a_urdfs_inertials_give_the_dynamics_of_the_equivalent_ron_file() {
    let ron = testkit::robot("iiwa7.ron").dynamics.expect("iiwa7.ron has masses");
    let text = iiwa_with_inertials(&ron);
    // The sensor is a second leaf: the chain's tip is named.
    let ends = ChainEnds { base_link: None, tip_link: Some("tool0".into()) };
    let chain = UrdfDocument::parse(&text, "iiwa7.urdf").and_then(|d| d.chain(&ends)).unwrap();
    let urdf = chain.description().dynamics.expect("every link has an inertial");
    assert_eq!(urdf.links.len(), ron.links.len());
    for (k, (a, b)) in urdf.links.iter().zip(&ron.links).enumerate() {
        assert!((a.mass_kg - b.mass_kg).abs() < 1e-12, "link {}: {} kg against {} kg", k + 1, a.mass_kg, b.mass_kg);
        let apart = (Vector3::from(a.com_m) - Vector3::from(b.com_m)).norm();
        assert!(apart < 1e-12, "link {}: centres {:?} and {:?} are {apart:e} m apart", k + 1, a.com_m, b.com_m);
    }
    assert_eq!(urdf.gravity_m_per_s2, ron.gravity_m_per_s2);
    // A URDF states no stiffness: none is invented.
    assert!(urdf.stiffness_nm_per_rad.is_empty());
    assert!(chain.joints_without_mass.is_empty());
}

#[test]
fn the_column_arms_column_carries_its_stages_collar_and_the_arms_base() {
    let robot = testkit::robot("column_arm.urdf");
    let dynamics = robot.dynamics.expect("column_arm.urdf gives every link a mass");
    // Joint 1 (the lift and its two mimic stages) moves stage 1, stage 2, the collar, stage 3,
    // the arm's base_link and base_link_inertia (fixed below stage 3): the file's masses.
    let column = [(60.0, 1.2), (45.0, 1.5), (8.0, 1.95), (35.0, 1.8), (0.5, 2.1), (4.0, 2.1)];
    let mass: f64 = column.iter().map(|(m, _)| m).sum();
    let height = column.iter().map(|(m, z)| m * z).sum::<f64>() / mass;
    let first = dynamics.links[0];
    assert!((first.mass_kg - 152.5).abs() < 1e-12 && (mass - 152.5).abs() < 1e-12, "{first:?}");
    let expected = Vector3::new(0.4, 0.0, height);
    assert!((Vector3::from(first.com_m) - expected).norm() < 1e-12, "{first:?} against {expected}");
    // The UR10's links one by one; the prism (0.2 kg, fixed below tool0) rides on the last joint.
    let arm: Vec<f64> = dynamics.links[1..].iter().map(|l| l.mass_kg).collect();
    let expected = [7.1, 12.7, 4.27, 2.0, 2.0, 0.365 + 0.2];
    for (k, (a, b)) in arm.iter().zip(expected).enumerate() {
        assert!((a - b).abs() < 1e-12, "joint {}: {a} kg, the file's {b} kg", k + 2);
    }
    // The track and the column's foot do not move: no joint carries them.
    assert!((dynamics.moving_mass_kg() - 152.5 - expected.iter().sum::<f64>()).abs() < 1e-9);
}

/// A two-joint arm, each link with a mass but `upper`'s, which is replaced.
const ARM: &str = r#"<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="upper">UPPER</link>
  <link name="tip"><inertial><origin xyz="0.1 0 0"/><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
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

fn arm(upper: &str) -> String {
    ARM.replace("UPPER", upper)
}

fn read(text: &str) -> Result<RobotDescription, errors::Error> {
    UrdfDocument::parse(text, "arm.urdf").and_then(|d| d.chain(&ChainEnds::default())).map(|c| c.description())
}

#[test]
fn a_joint_whose_body_has_no_inertial_leaves_the_robot_without_masses() {
    let good = "<inertial><mass value=\"3\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>";
    let with = read(&arm(good)).unwrap().dynamics.expect("both links have masses");
    assert_eq!(with.links.iter().map(|l| l.mass_kg).collect::<Vec<_>>(), vec![3.0, 2.0]);
    // The origin left out is the link's frame: upper's centre is the shoulder's origin.
    assert_eq!(with.links[0].com_m, [0.0, 0.0, 0.5]);
    assert_eq!(with.links[1].com_m, [0.5, 0.0, 0.5]);
    let chain = UrdfDocument::parse(&arm(""), "arm.urdf").unwrap().chain(&ChainEnds::default()).unwrap();
    assert_eq!(chain.joints_without_mass, vec![1]);
    assert_eq!(chain.description().dynamics, None);
}

#[test]
fn bad_inertials_are_refused_at_their_element() {
    let inertia = "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>";
    let with_mass = |mass: &str| format!("\n    <inertial>\n      <mass value=\"{mass}\"/>{inertia}</inertial>");
    let with_origin = |attributes: &str| {
        format!("\n    <inertial>\n      <origin {attributes}/><mass value=\"1\"/>{inertia}</inertial>")
    };
    for (case, upper, position, words) in [
        ("negative mass", with_mass("-1"), (6, 7), "<mass value=\"-1\"> must be a number of kilograms"),
        ("NaN mass", with_mass("NaN"), (6, 7), "<mass value=\"NaN\">"),
        ("infinite mass", with_mass("inf"), (6, 7), "<mass value=\"inf\">"),
        ("a thousand tonnes and more", with_mass("2e6"), (6, 7), "from 0 to 1e6"),
        ("a word for a mass", with_mass("heavy"), (6, 7), "<mass value=\"heavy\">"),
        ("no mass", format!("\n    <inertial>{inertia}</inertial>"), (5, 5), "has no <mass value=..>"),
        ("two numbers", with_origin("xyz=\"0 0\""), (6, 7), "<origin xyz=\"0 0\"> must be three finite numbers"),
        ("a word among them", with_origin("xyz=\"0 a 0 0\""), (6, 7), "<origin xyz=\"0 a 0 0\">"),
        ("NaN centre", with_origin("xyz=\"0 NaN 0\""), (6, 7), "<origin xyz=\"0 NaN 0\">"),
        ("infinite rpy", with_origin("rpy=\"0 inf 0\""), (6, 7), "<origin rpy=\"0 inf 0\">"),
        ("beyond a kilometre", with_origin("xyz=\"0 0 2e3\""), (6, 7), "beyond 1000 m"),
    ] {
        let text = arm(&format!("{upper}\n  "));
        let error = match read(&text) {
            Ok(_) => panic!("{case}: read, not refused"),
            Err(e) => e,
        };
        let (Some((line, column)), ErrorKind::UrdfFormat { message }) = (error.position(), error.kind()) else {
            panic!("{case}: {error}");
        };
        assert_eq!((line as usize, column), position, "{case}: {error}");
        assert!(error.to_string().starts_with("arm.urdf:"), "{case}: {error}");
        assert!(message.contains("link 'upper'") && message.contains(words), "{case}: {message}");
    }
}
