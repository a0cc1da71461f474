//! The one list of effect kinds, shared by the simulator ([`crate::Effects`]), the fit and the
//! model file (`effects::IdentifiedEffect`), the diagnosis (`diagnose::Effect`) and the command
//! line (`--effects`, `calib simulate`). Everything that enumerates the kinds is generated from
//! [`effect_kinds!`](crate::effect_kinds), so that adding an effect is one line here and one file
//! in `effects` (its module is declared from this line), and simulating it one more file here
//! (see docs/ARCHITECTURE.md, "Adding an effect").

/// Calls the macro `$callback` with the list of effect kinds, in a fixed order:
///
/// ```text
/// identified { $( #[doc] Kind spec_name: KindTerm $( => spec_name $(| "former")?: KindModel )?, )* }
/// simulated { $( #[doc] Kind spec_name => spec_name: KindModel, )* }
/// ```
///
/// `identified` kinds have a regressor in the `effects` crate: the type `KindTerm` in its module
/// `spec_name` (the file `crates/effects/src/spec_name.rs`, declared from this list), implementing
/// its `EffectTerm`; each is an item of `--effects` and a candidate the diagnosis can name. The
/// names keep the two sides apart: `effects::GearPeriodicTerm` is what the fit identifies and a
/// model file holds, `loadsim::GearPeriodicModel` the simulator's ground truth.
/// `simulated` kinds exist only in the simulator. `spec_name` is the SPEC's name (serde, the
/// `--effects` item, the diagnosis JSON). Where a kind is simulated, the field of
/// [`crate::Effects`] that switches it on has the same name (written twice because a macro cannot
/// make a field from the kind's name), and `KindModel` is the type it holds there, which
/// implements [`crate::SimulatedEffect`] (the effect's simulation: its checks and its place in the
/// forward model). `| "former"` gives the field's spelling in effects files before SPEC version 5,
/// which still reads (serde needs it as a literal). An
/// identified kind may have no simulation: it is then fitted, diagnosed and read from model files,
/// and [`EffectKind::simulated_field`] is `None`.
///
/// ```
/// macro_rules! names {
///     (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
///      simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
///         [$(stringify!($name)),*]
///     };
/// }
/// let identified = loadsim::effect_kinds!(names);
/// assert_eq!(identified[0], "joint_compliance");
/// ```
#[macro_export]
macro_rules! effect_kinds {
    ($callback:ident) => {
        $callback! {
            identified {
                /// Joint compliance under gravity and payload.
                JointCompliance joint_compliance: JointComplianceTerm
                    => joint_compliance | "compliance": $crate::JointComplianceModel,
                /// Backlash following the sign of the static torque.
                Backlash backlash: BacklashTerm => backlash: $crate::BacklashModel,
                /// A periodic error of a joint in its own angle (gear or encoder).
                GearPeriodic gear_periodic: GearPeriodicTerm => gear_periodic | "periodic": $crate::GearPeriodicModel,
                /// Thermal growth of the links with `temp_c`.
                Thermal thermal: ThermalTerm => thermal: $crate::ThermalModel,
                /// Drift of the robot's placement with `t_s`.
                TimeDrift time_drift: TimeDriftTerm => time_drift | "drift": $crate::TimeDriftModel,
                /// A link bending under the gravity moment of everything beyond it.
                LinkDeflection link_deflection: LinkDeflectionTerm
                    => link_deflection | "deflection": $crate::LinkDeflectionModel,
                /// A periodic error of a linear axis in its own position, per screw or rack pitch.
                ScrewPeriodic screw_periodic: ScrewPeriodicTerm => screw_periodic | "screw": $crate::ScrewPeriodicModel,
            }
            simulated {
                /// Tracker measurement noise.
                TrackerNoise tracker_noise => tracker_noise: $crate::TrackerNoiseModel,
                /// A joint error driven by other joints' angles; no candidate of the diagnosis models it.
                Coupling coupling => coupling: $crate::CouplingModel,
            }
        }
    };
}

macro_rules! effect_kind_enum {
    (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
     simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
        /// The kinds of effect, named as in the SPEC (`--effects`, the model file, the `calib
        /// diagnose` JSON), generated from [`effect_kinds!`](crate::effect_kinds).
        #[non_exhaustive]
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum EffectKind {
            $( $(#[$doc])* $kind, )*
            $( $(#[$sdoc])* $skind, )*
        }

        impl EffectKind {
            /// Every kind, in the list's order.
            pub const ALL: &'static [EffectKind] = &[$(EffectKind::$kind,)* $(EffectKind::$skind,)*];

            /// The kinds the fit identifies and the diagnosis can name, in the list's order.
            pub const IDENTIFIED: &'static [EffectKind] = &[$(EffectKind::$kind,)*];

            /// The SPEC name (`joint_compliance`, `gear_periodic`, …).
            pub fn name(self) -> &'static str {
                match self {
                    $( EffectKind::$kind => stringify!($name), )*
                    $( EffectKind::$skind => stringify!($sname), )*
                }
            }

            /// The kind of a SPEC name.
            pub fn from_name(name: &str) -> Option<EffectKind> {
                Self::ALL.iter().copied().find(|k| k.name() == name)
            }

            /// Whether the fit identifies this kind (it has a regressor in `effects`).
            pub fn is_identified(self) -> bool {
                Self::IDENTIFIED.contains(&self)
            }

            /// The field of `calib simulate`'s effects file that holds it (the SPEC name);
            /// `None` for a kind the simulator does not model.
            pub fn simulated_field(self) -> Option<&'static str> {
                match self {
                    $( EffectKind::$kind => {
                        let field: &[&'static str] = &[$(stringify!($field))?];
                        field.first().copied()
                    } )*
                    $( EffectKind::$skind => Some(stringify!($sfield)), )*
                }
            }

            /// The spelling of [`EffectKind::simulated_field`] in effects files before SPEC
            /// version 5, where it was another (still read); `None` where it was the same.
            pub fn former_field(self) -> Option<&'static str> {
                match self {
                    $( EffectKind::$kind => {
                        let former: &[&'static str] = &[$($($former)?)?];
                        former.first().copied()
                    } )*
                    $( EffectKind::$skind => None, )*
                }
            }
        }
    };
}

use serde::{Deserialize, Serialize};

effect_kinds!(effect_kind_enum);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Effects;

    #[test]
    fn the_serde_names_are_the_spec_names_and_read_back() {
        for &kind in EffectKind::ALL {
            let text = ron::to_string(&kind).unwrap();
            assert_eq!(text, kind.name());
            assert_eq!(ron::from_str::<EffectKind>(&text).unwrap(), kind);
            assert_eq!(EffectKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(EffectKind::from_name("gear"), None);
        assert!(EffectKind::GearPeriodic.is_identified() && !EffectKind::Coupling.is_identified());
        assert_eq!(EffectKind::GearPeriodic.simulated_field(), Some("gear_periodic"));
        assert_eq!(EffectKind::GearPeriodic.former_field(), Some("periodic"));
        assert_eq!(EffectKind::Backlash.former_field(), None);
    }

    /// One name per effect: the field of `Effects` that switches a kind on (and the effects
    /// file's field) is the kind's SPEC name, for every kind the simulator models.
    #[test]
    fn every_simulated_kind_is_switched_on_by_a_field_of_its_own_name() {
        let on = Effects {
            joint_compliance: Some(Default::default()),
            gear_periodic: Some(Default::default()),
            time_drift: Some(Default::default()),
            ..Effects::default()
        };
        for &kind in EffectKind::ALL {
            if let Some(field) = kind.simulated_field() {
                assert_eq!(field, kind.name(), "{kind:?}");
            }
        }
        let text = ron::to_string(&on).unwrap();
        for name in ["joint_compliance", "gear_periodic", "time_drift"] {
            assert!(text.contains(&format!("{name}:")), "{text}");
        }
    }
}
