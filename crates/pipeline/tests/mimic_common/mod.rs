//! What the mimic tests share: the chain of a URDF text, the chain walked joint by joint without
//! the fold, and the refusals placed at the `<mimic>` element.

#![allow(dead_code)] // each test file uses its own part

use lie::{SE3, SO3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::ErrorKind;
use robot::{ChainEnds, RobotDescription, StepMotion, UrdfChain, UrdfDocument};

pub fn chain(text: &str, ends: &ChainEnds) -> UrdfChain {
    UrdfDocument::parse(text, "arm.urdf").and_then(|d| d.chain(ends)).unwrap_or_else(|e| panic!("{e}"))
}

/// The tip of `chain` at actuated joint values `q`, walking every URDF joint: the actuated ones
/// (movable joints without `<mimic>`, in chain order, or beside the chain before the first of
/// their stages) at `q`, each mimic joint at `multiplier · q_followed + offset`. Written without
/// the fold.
pub fn joint_by_joint(chain: &UrdfChain, q: &[f64]) -> SE3 {
    let mut actuated: Vec<&str> = Vec::new();
    for step in chain.steps.iter().filter(|s| s.motion != StepMotion::Fixed) {
        let name = step.mimic.as_ref().map_or(step.joint.as_str(), |m| m.joint.as_str());
        if !actuated.contains(&name) {
            actuated.push(name);
        }
    }
    let value_of = |name: &str| q[actuated.iter().position(|a| *a == name).expect("an actuated joint")];
    let mut frame = SE3::identity();
    for step in &chain.steps {
        let value = match &step.mimic {
            Some(m) => m.multiplier * value_of(&m.joint) + m.offset,
            None if step.motion == StepMotion::Fixed => 0.0,
            None => value_of(&step.joint),
        };
        let motion = match step.motion {
            StepMotion::Fixed => SE3::identity(),
            StepMotion::Revolute { .. } => SE3::new(SO3::exp(&(step.axis * value)), Vector3::zeros()),
            StepMotion::Prismatic { .. } => SE3::from_translation(step.axis * value),
        };
        frame = frame * step.from_to * motion;
    }
    frame
}

pub fn random_q(robot: &RobotDescription, rng: &mut ChaCha8Rng) -> Vec<f64> {
    robot
        .limits()
        .iter()
        .map(
            |&(lo, hi)| {
                if lo.is_finite() && hi.is_finite() { rng.random_range(lo..hi) } else { rng.random_range(-3.0..3.0) }
            },
        )
        .collect()
}

/// Largest difference between the description's tool pose and the joint-by-joint walk.
pub fn largest_difference(chain: &UrdfChain, seed: u64) -> f64 {
    let robot = chain.description();
    let model = robot.nominal_model().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..50)
        .map(|_| {
            let q = random_q(&robot, &mut rng);
            let folded = model.forward(&q, 0).unwrap();
            (folded.to_matrix() - joint_by_joint(chain, &q).to_matrix()).norm()
        })
        .fold(0.0, f64::max)
}

/// The refusal of `text`: line, column and message, checked to name the file first.
pub fn refusal(text: &str) -> (usize, usize, String) {
    match UrdfDocument::parse(text, "arm.urdf").and_then(|d| d.chain(&ChainEnds::default())) {
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

/// The 1-based line and column of the first `<mimic` after `joint`'s element in `text`.
pub fn mimic_position(text: &str, joint: &str) -> (usize, usize) {
    let start = text.find(&format!("<joint name=\"{joint}\"")).expect("the joint");
    let at = start + text[start..].find("<mimic").expect("its mimic");
    let before = &text[..at];
    (before.matches('\n').count() + 1, before.rsplit('\n').next().unwrap().chars().count() + 1)
}

pub fn assert_refused(text: &str, joint: &str, words: &[&str]) {
    let (line, column, message) = refusal(text);
    assert_eq!((line, column), mimic_position(text, joint), "{message}");
    assert!(message.starts_with(&format!("mimic joint '{joint}': ")), "{message}");
    for word in words {
        assert!(message.contains(word), "{word:?} not in: {message}");
    }
}
