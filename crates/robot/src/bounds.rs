//! Sanity bounds on the values a robot or model file may hold.

use lie::SE3;

/// The largest translation a model file may hold, m: a kilometre, two orders of magnitude beyond
/// any robot cell. It is a sanity bound on a file, not a tuning constant: a corrupt or edited value
/// beyond it (1e308 is finite) makes the products of forward kinematics and gravity torques
/// overflow, and the model would then predict NaN poses instead of being refused here.
pub const MAX_TRANSLATION_M: f64 = 1.0e3;

/// The range of a linear joint's screw lead (a robot file's `pitch_mm`, a `screw_periodic` item's
/// pitch), mm: the finest ball-screw leads sold are 0.5 mm (miniature screws, THK/NSK catalogues),
/// and a rack's pinion turns once in well under 10 m; a value outside is a unit mistake (metres for
/// millimetres, or the reverse) or a typing error.
pub const PITCH_BOUNDS_MM: (f64, f64) = (0.01, 10_000.0);

/// The first translation among `transforms` that is not finite or beyond [`MAX_TRANSLATION_M`],
/// with its position in the list.
pub fn bad_translation(transforms: impl Iterator<Item = SE3>) -> Option<(usize, f64)> {
    transforms.enumerate().find_map(|(k, t)| {
        t.translation().iter().copied().find(|v| !v.is_finite() || v.abs() > MAX_TRANSLATION_M).map(|v| (k, v))
    })
}
