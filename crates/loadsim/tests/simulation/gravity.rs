//! Gravity torque against the finite-difference gradient of the potential energy, and the torque
//! regressor against the torque.

use crate::robot::{irb4400, random_q, with_tool};
use lie::Vector3;
use loadsim::{
    Counterbalance, LinkInertia, Payload, RobotDynamics, gravity_regressor, gravity_torque, potential_energy,
    static_torque,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `−∂V/∂q` by central differences, step 1e-6 rad.
fn minus_gradient(dynamics: &RobotDynamics, model: &poe::LocalPoe, q: &[f64], payload: &Payload) -> Vec<f64> {
    let h = 1e-6;
    (0..q.len())
        .map(|j| {
            let mut plus = q.to_vec();
            let mut minus = q.to_vec();
            plus[j] += h;
            minus[j] -= h;
            let vp = potential_energy(model, dynamics, &plus, 0, payload).unwrap();
            let vm = potential_energy(model, dynamics, &minus, 0, payload).unwrap();
            -(vp - vm) / (2.0 * h)
        })
        .collect()
}

fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    for (j, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what}: joint {} {x} vs {y}", j + 1);
    }
}

#[test]
fn gravity_torque_is_minus_the_gradient_of_the_potential_energy_without_payload() {
    let robot = irb4400();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let none = Payload::default();
        let tau = gravity_torque(&robot.model, &robot.dynamics, &q, 0, &none).unwrap();
        // Torques reach ~3000 N·m; central differences of V (~1e4 J) are good to ~1e-3 N·m.
        assert_close(&tau, &minus_gradient(&robot.dynamics, &robot.model, &q, &none), 1e-2, "links only");
        assert!(tau[1].abs() > 10.0, "joint 2 carries the arm's weight");
    }
}

#[test]
fn gravity_torque_is_minus_the_gradient_of_the_potential_energy_with_an_offset_payload() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let payload = Payload {
            mass_kg: rng.random_range(0.5..60.0),
            com_offset_m: [rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1), rng.random_range(0.0..0.2)],
        };
        let tau = gravity_torque(&model, &robot.dynamics, &q, 0, &payload).unwrap();
        assert_close(&tau, &minus_gradient(&robot.dynamics, &model, &q, &payload), 1e-2, "with payload");
    }
}

#[test]
fn payload_alone_torque_matches_its_potential_and_vanishes_for_zero_mass() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let massless = crate::robot::massless(vec![1e6; 6]);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..10 {
        let q = random_q(&robot.ranges, &mut rng);
        let payload = Payload::at_tool(7.5);
        let tau = gravity_torque(&model, &massless, &q, 0, &payload).unwrap();
        assert_close(&tau, &minus_gradient(&massless, &model, &q, &payload), 1e-4, "payload only");
        assert!(tau[0].abs() < 1e-9, "joint 1 is vertical: gravity has no moment about it");
        let zero = gravity_torque(&model, &massless, &q, 0, &Payload::default()).unwrap();
        assert!(zero.iter().all(|t| *t == 0.0));
    }
}

#[test]
fn regressor_times_inertial_parameters_is_the_gravity_torque() {
    let robot = irb4400();
    let g = Vector3::from(robot.dynamics.gravity_m_per_s2);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        // Random masses and centres, so that every column of Y is exercised.
        let dynamics = RobotDynamics {
            links: (0..6)
                .map(|_| LinkInertia {
                    mass_kg: rng.random_range(1.0..200.0),
                    com_m: [rng.random_range(-0.5..1.5), rng.random_range(-0.3..0.3), rng.random_range(0.0..2.0)],
                })
                .collect(),
            ..robot.dynamics.clone()
        };
        let y = gravity_regressor(&robot.model, &q, &g).unwrap();
        assert_eq!(y.shape(), (6, 24));
        let predicted = &y * dynamics.inertial_parameters();
        let tau = gravity_torque(&robot.model, &dynamics, &q, 0, &Payload::default()).unwrap();
        assert_close(predicted.as_slice(), &tau, 1e-8, "Y pi");
        assert_close(
            predicted.as_slice(),
            &minus_gradient(&dynamics, &robot.model, &q, &Payload::default()),
            1e-2,
            "-dV/dq",
        );
    }
}

#[test]
fn regressor_is_upper_block_triangular_because_a_joint_does_not_move_the_links_before_it() {
    let robot = irb4400();
    let y = gravity_regressor(&robot.model, &[0.3, 0.2, -0.1, 0.5, 0.7, -0.4], &Vector3::new(0.0, 0.0, -9.81)).unwrap();
    for j in 0..6 {
        for k in 0..j {
            for c in 0..4 {
                assert_eq!(y[(j, 4 * k + c)], 0.0, "joint {} sees link {}", j + 1, k + 1);
            }
        }
    }
}

#[test]
fn counterbalance_torque_is_minus_the_gradient_of_the_spring_potential_and_linear_in_force_and_rate() {
    let balancer = Counterbalance {
        joint_index: 1,
        anchor_radius_m: 0.3,
        attachment_radius_m: 0.2,
        angle_at_zero_rad: 0.25,
        force_at_zero_n: 3000.0,
        stiffness_n_per_m: 25000.0,
    };
    let l0 = balancer.spring_length_m(0.0);
    let energy = |q: f64| {
        let stretch = balancer.spring_length_m(q) - l0;
        balancer.force_at_zero_n * stretch + 0.5 * balancer.stiffness_n_per_m * stretch * stretch
    };
    for q in [-1.2, -0.5, 0.0, 0.3, 1.1, 1.6] {
        let h = 1e-6;
        let fd = -(energy(q + h) - energy(q - h)) / (2.0 * h);
        assert!((balancer.torque_nm(q) - fd).abs() < 1e-4, "q {q}: {} vs {fd}", balancer.torque_nm(q));
        let [a, b] = balancer.regressor(q);
        assert!((a * 3000.0 + b * 25000.0 - balancer.torque_nm(q)).abs() < 1e-9);
    }
}

#[test]
fn static_torque_adds_the_balancer_on_its_joint_only() {
    let robot = irb4400();
    let q = [0.1, 0.6, -0.3, 0.2, 0.4, 0.0];
    let balancer = robot.dynamics.counterbalance.expect("fixture has a balancer");
    let with = static_torque(&robot.model, &robot.dynamics, &q, 0, &Payload::default()).unwrap();
    let without = gravity_torque(&robot.model, &robot.dynamics, &q, 0, &Payload::default()).unwrap();
    for j in 0..6 {
        let expected = if j == 1 { without[j] + balancer.torque_nm(q[1]) } else { without[j] };
        assert!((with[j] - expected).abs() < 1e-9);
    }
    assert!(with[1].abs() < without[1].abs(), "the balancer relieves joint 2 when the arm leans forward");
}

/// On a prismatic joint the generalised force of gravity is a force along the axis (N, from the
/// spatial twist `(v, 0)`), what a linear axis's compliance and backlash act under: a
/// tilted track carrying a two-joint arm, against the finite-difference gradient of `V` and the
/// regressor, with a payload off the tool.
#[test]
fn a_prismatic_joints_gravity_force_is_minus_the_gradient_of_the_potential_energy() {
    use poe::{JointAxis, JointKind, LocalPoe};
    let axis =
        |kind, d: [f64; 3], p: [f64; 3]| JointAxis { kind, direction: Vector3::from(d).normalize(), point: p.into() };
    let model = LocalPoe::from_zero_configuration(
        &[
            axis(JointKind::Prismatic, [1.0, 0.0, 0.4], [0.0, 0.0, 0.0]),
            axis(JointKind::Revolute, [0.0, 0.0, 1.0], [0.2, 0.0, 0.5]),
            axis(JointKind::Revolute, [0.0, 1.0, 0.0], [0.2, 0.0, 0.9]),
        ],
        lie::SE3::from_translation(Vector3::new(0.9, 0.0, 0.9)),
    )
    .unwrap();
    let dynamics = RobotDynamics {
        links: vec![
            LinkInertia { mass_kg: 80.0, com_m: [0.1, 0.05, 0.3] },
            LinkInertia { mass_kg: 20.0, com_m: [0.25, 0.0, 0.7] },
            LinkInertia { mass_kg: 8.0, com_m: [0.6, 0.02, 0.9] },
        ],
        stiffness_nm_per_rad: Vec::new(),
        counterbalance: None,
        gravity_m_per_s2: loadsim::FLOOR_GRAVITY_M_PER_S2,
    };
    let payload = Payload { mass_kg: 5.0, com_offset_m: [0.02, 0.0, 0.05] };
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for _ in 0..20 {
        let q = [rng.random_range(0.0..2.0), rng.random_range(-3.0..3.0), rng.random_range(-1.5..1.5)];
        let force = gravity_torque(&model, &dynamics, &q, 0, &payload).unwrap();
        assert_close(&force, &minus_gradient(&dynamics, &model, &q, &payload), 1e-3, "prismatic arm");
        // The whole moving mass, 113 kg, pulled down the track's 0.4/1.08 slope.
        let along = 9.81 * 113.0 * 0.4 / (1.0f64 + 0.16).sqrt();
        assert!((force[0] + along).abs() < 1e-9, "joint 1: {} N against {} N", force[0], -along);
        let y = gravity_regressor(&model, &q, &Vector3::from(dynamics.gravity_m_per_s2)).unwrap();
        let links = gravity_torque(&model, &dynamics, &q, 0, &Payload::default()).unwrap();
        assert_close((&y * dynamics.inertial_parameters()).as_slice(), &links, 1e-8, "Y pi");
    }
}
