//! Sanity bounds on the values a robot or model file may hold.

use lie::SE3;

/// The largest translation a model file may hold, m: a kilometre, two orders of magnitude beyond
/// any robot cell. It is a sanity bound on a file, not a tuning constant: a corrupt or edited value
/// beyond it (1e308 is finite) makes the products of forward kinematics and gravity torques
/// overflow, and the model would then predict NaN poses instead of being refused here.
pub const MAX_TRANSLATION_M: f64 = 1.0e3;

/// The first translation among `transforms` that is not finite or beyond [`MAX_TRANSLATION_M`],
/// with its position in the list.
pub fn bad_translation(transforms: impl Iterator<Item = SE3>) -> Option<(usize, f64)> {
    transforms.enumerate().find_map(|(k, t)| {
        t.translation().iter().copied().find(|v| !v.is_finite() || v.abs() > MAX_TRANSLATION_M).map(|v| (k, v))
    })
}
