//! The effects the diagnosis's candidates do not parameterise exactly: a coupled joint error,
//! gear errors of high order with any phase, and gravity on a tilted base (which loads joint 1).

use crate::robot::{iiwa7, irb4400, random_q, with_tool};
use loadsim::{
    CouplingFactor, CouplingModel, CouplingTerm, EffectKind, Effects, Error, GearPeriodicModel, Harmonic, Payload,
    PoseContext, RobotDynamics, SimulatedCell, gravity_torque, periodic_joint_regressor, tilted_base_gravity,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Joint 3's error driven by q2 and q4 (0-based 2 by 1 and 3).
fn joint3_by_q2_q4(amplitude_rad: f64) -> CouplingModel {
    CouplingModel {
        terms: vec![CouplingTerm {
            joint_index: 2,
            amplitude_rad,
            factors: vec![
                CouplingFactor { source_joint_index: 1, order: 2.0, phase_rad: 0.4 },
                CouplingFactor { source_joint_index: 3, order: 1.0, phase_rad: -1.1 },
            ],
        }],
    }
}

#[test]
fn a_coupled_error_moves_only_its_joint_by_the_product_of_its_factors() {
    let robot = irb4400();
    let cell = SimulatedCell::new(with_tool(&robot.model, 0.2), None);
    let effects = Effects { coupling: Some(joint3_by_q2_q4(1e-3)), ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(60);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let offsets = effects.joint_offsets(&cell, &q, &PoseContext::default()).unwrap();
        let expected = 1e-3 * (2.0 * q[1] + 0.4).cos() * (q[3] - 1.1).cos();
        for (j, dq) in offsets.of(EffectKind::Coupling).iter().enumerate() {
            let want = if j == 2 { expected } else { 0.0 };
            assert!((dq - want).abs() < 1e-18, "joint {}: {dq} vs {want}", j + 1);
        }
        assert_eq!(offsets.total(), offsets.of(EffectKind::Coupling));
        // It does not depend on joint 3's own angle.
        let mut turned = q.clone();
        turned[2] += rng.random_range(-1.0..1.0);
        assert_eq!(
            effects.joint_offsets(&cell, &turned, &PoseContext::default()).unwrap().of(EffectKind::Coupling),
            offsets.of(EffectKind::Coupling)
        );
    }
}

#[test]
fn bad_coupling_settings_are_refused() {
    let n = 6;
    let mut own = joint3_by_q2_q4(1e-3);
    own.terms[0].factors[1].source_joint_index = 2;
    assert_eq!(own.validate(n), Err(Error::SelfCoupling { joint_index: 2 }));
    let mut outside = joint3_by_q2_q4(1e-3);
    outside.terms[0].factors[0].source_joint_index = 6;
    assert_eq!(
        outside.validate(n),
        Err(Error::from(dynamics::Error::UnknownJoint {
            field: "coupling.source_joint_index",
            joint_index: 6,
            joint_count: 6
        }))
    );
    let mut empty = joint3_by_q2_q4(1e-3);
    empty.terms[0].factors.clear();
    assert_eq!(
        empty.validate(n),
        Err(Error::from(dynamics::Error::LengthMismatch { field: "coupling.factors", given: 0, expected: 1 }))
    );
    let not_a_number = joint3_by_q2_q4(f64::NAN);
    assert!(matches!(
        not_a_number.validate(n),
        Err(Error::Dynamics { source: dynamics::Error::InvalidParameter { field: "coupling.amplitude_rad", .. } })
    ));
    let cell = SimulatedCell::new(irb4400().model, None);
    let effects = Effects { coupling: Some(own), ..Effects::default() };
    assert_eq!(
        effects.true_pose(&cell, &[0.0; 6], &PoseContext::default()),
        Err(Error::SelfCoupling { joint_index: 2 })
    );
}

#[test]
fn a_coupling_reads_from_ron_under_its_own_field() {
    let text = "(coupling: Some((terms: [(joint_index: 2, amplitude_rad: 1e-3, factors: [\
                (source_joint_index: 1, order: 2.0, phase_rad: 0.4), \
                (source_joint_index: 3, order: 1.0, phase_rad: -1.1)])])))";
    let effects: Effects = ron::from_str(text).unwrap();
    assert_eq!(effects.coupling, Some(joint3_by_q2_q4(1e-3)));
    assert!(effects.joint_compliance.is_none() && effects.gear_periodic.is_none());
    let written = ron::to_string(&effects).unwrap();
    assert_eq!(ron::from_str::<Effects>(&written).unwrap(), effects);
}

#[test]
fn a_gear_error_of_order_forty_with_any_phase_on_joint_1_is_its_cos_sin_regressor() {
    let robot = irb4400();
    let cell = SimulatedCell::new(with_tool(&robot.model, 0.2), None);
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    let harmonics: Vec<Harmonic> = [1.0, 17.0, 40.0]
        .iter()
        .map(|&order| Harmonic {
            joint_index: 0,
            order,
            amplitude_rad: rng.random_range(1e-5..1e-4),
            phase_rad: rng.random_range(0.0..std::f64::consts::TAU),
        })
        .collect();
    let effects =
        Effects { gear_periodic: Some(GearPeriodicModel { harmonics: harmonics.clone() }), ..Effects::default() };
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let offsets = effects.joint_offsets(&cell, &q, &PoseContext::default()).unwrap();
        let linear: f64 = harmonics
            .iter()
            .map(|h| {
                let [a, b] = h.cos_sin_coefficients();
                let [c, s] = periodic_joint_regressor(q[0], h.order);
                a * c + b * s
            })
            .sum();
        assert!((offsets.of(EffectKind::GearPeriodic)[0] - linear).abs() < 1e-15);
        assert!(offsets.of(EffectKind::GearPeriodic)[1..].iter().all(|v| *v == 0.0));
    }
}

#[test]
fn a_tilted_base_keeps_gravitys_size_and_loads_joint_1() {
    let floor = tilted_base_gravity(0.0, 0.3);
    assert_eq!(floor, loadsim::FLOOR_GRAVITY_M_PER_S2.map(|g| if g == 0.0 { 0.0 } else { g }));
    let ceiling = tilted_base_gravity(std::f64::consts::PI, 0.3);
    assert!((ceiling[2] - 9.81).abs() < 1e-12);
    let wall = tilted_base_gravity(std::f64::consts::FRAC_PI_2, 0.0);
    assert!(wall[2].abs() < 1e-12, "a wall mount's gravity lies in the base xy plane: {wall:?}");
    for tilt in [0.2, 1.0, 2.5] {
        let g = tilted_base_gravity(tilt, 1.3);
        assert!((g.iter().map(|x| x * x).sum::<f64>().sqrt() - 9.81).abs() < 1e-12);
        assert!((g[2] + 9.81 * tilt.cos()).abs() < 1e-12, "tilted by {tilt}: {g:?}");
    }
    // Joint 1 carries no gravity torque on the floor, and does on a wall.
    let robot = iiwa7();
    let q = [0.3, 0.8, 0.0, -0.5, 0.0, 0.4, 0.0];
    let payload = Payload::at_tool(5.0);
    let on_floor = gravity_torque(&robot.model, &robot.dynamics, &q, 0, &payload).unwrap();
    let walled = RobotDynamics { gravity_m_per_s2: wall, ..robot.dynamics.clone() };
    let on_wall = gravity_torque(&robot.model, &walled, &q, 0, &payload).unwrap();
    assert!(on_floor[0].abs() < 1e-9, "{}", on_floor[0]);
    assert!(on_wall[0].abs() > 10.0, "joint 1 on a wall: {} N·m", on_wall[0]);
}
