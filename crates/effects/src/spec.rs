//! `--effects LIST|auto` (SPEC v2): which non-geometric effects a fit identifies with the
//! geometry. Items are `joint_compliance`, `gear_periodic:JOINT:HARMONICS`, `backlash:JOINT`,
//! `thermal`, `time_drift`, `link_deflection:JOINT` and `screw_periodic:JOINT:PITCH_MM:HARMONICS`,
//! comma separated; joints are 1-based. A bad item is refused with its
//! position in the argument and what is wrong with it. The names are those of
//! [`EffectKind::IDENTIFIED`] and each kind's arguments its `NewEffect::ARGUMENTS` (module `term`),
//! so a new effect is parsed and printed without a change here.

use crate::ErrorKind;
use crate::IdentifiedEffect;
use errors::Error;
use loadsim::EffectKind;
use std::fmt;
use std::str::FromStr;

pub use crate::error_kind::{EffectListFault, MAX_HARMONICS};
pub use robot::PITCH_BOUNDS_MM;

/// What an `--effects` item takes after its name, in order (`gear_periodic:JOINT:HARMONICS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Argument {
    /// A 1-based joint, at least 1 ([`EffectListFault::Joint`] otherwise).
    Joint,
    /// The highest harmonic order of a series, `1..=MAX_HARMONICS` ([`EffectListFault::Harmonics`]).
    Harmonics,
    /// A linear axis's screw lead (or rack pinion's circumference), mm, within [`PITCH_BOUNDS_MM`]
    /// ([`EffectListFault::Pitch`]).
    Pitch,
}

/// One effect of an `--effects` list, as the user names it: a kind the fit identifies and the
/// arguments its item takes ([`EffectSpec::arguments`], in that order after the name).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectSpec {
    /// The kind (one of [`EffectKind::IDENTIFIED`]).
    pub kind: EffectKind,
    /// The 1-based joint, for a kind that takes one.
    pub joint: Option<usize>,
    /// The highest harmonic order (harmonics `1..=harmonics`), for a kind that takes it.
    pub harmonics: Option<u32>,
    /// The pitch, mm, for a kind that takes it (`screw_periodic`); `None` in an item made by
    /// `--effects auto`, whose fit takes the robot file's `pitch_mm` of the joint.
    pub pitch_mm: Option<f64>,
}

// The parser admits only finite pitches (within `PITCH_BOUNDS_MM`), so equality is reflexive.
impl Eq for EffectSpec {}

impl std::hash::Hash for EffectSpec {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        (self.kind, self.joint, self.harmonics, self.pitch_mm.map(f64::to_bits)).hash(state);
    }
}

impl EffectSpec {
    /// An item of `kind` with no arguments (`joint_compliance`, `thermal`, `time_drift`).
    pub fn new(kind: EffectKind) -> Self {
        Self { kind, joint: None, harmonics: None, pitch_mm: None }
    }

    /// An item of `kind` on 1-based joint `joint` (`backlash:JOINT`).
    pub fn on_joint(kind: EffectKind, joint: usize) -> Self {
        Self { joint: Some(joint), ..Self::new(kind) }
    }

    /// A gear series of 1-based joint `joint` with harmonics `1..=harmonics`.
    pub fn gear_periodic(joint: usize, harmonics: u32) -> Self {
        Self { harmonics: Some(harmonics), ..Self::on_joint(EffectKind::GearPeriodic, joint) }
    }

    /// The 1-based joint the item names, if any.
    pub fn joint(&self) -> Option<usize> {
        self.joint
    }

    /// What the item takes after its name, in order.
    pub fn arguments(&self) -> &'static [Argument] {
        IdentifiedEffect::arguments(self.kind)
    }

    /// Whether two items fit the same parameters (the same effect on the same joint).
    pub fn overlaps(&self, other: &EffectSpec) -> bool {
        self.kind == other.kind && self.joint == other.joint
    }
}

impl fmt::Display for EffectSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        for argument in self.arguments() {
            match (argument, self.joint, self.harmonics, self.pitch_mm) {
                (Argument::Joint, Some(joint), _, _) => write!(f, ":{joint}")?,
                (Argument::Harmonics, _, Some(harmonics), _) => write!(f, ":{harmonics}")?,
                (Argument::Pitch, _, _, Some(pitch)) => write!(f, ":{pitch}")?,
                _ => {}
            }
        }
        Ok(())
    }
}

impl EffectSpec {
    /// The 0-based joint of an item that takes one (refused as a missing argument otherwise).
    pub(crate) fn joint_index(&self) -> Result<usize, Error> {
        self.joint.map(|j| j - 1).ok_or_else(|| self.missing())
    }

    /// The harmonics of an item that takes them.
    pub(crate) fn required_harmonics(&self) -> Result<u32, Error> {
        self.harmonics.ok_or_else(|| self.missing())
    }

    /// The pitch of an item that takes one, m: the item's, else `stated` (the robot file's, mm).
    pub(crate) fn required_pitch_m(&self, stated: Option<f64>) -> Result<f64, Error> {
        self.pitch_mm.or(stated).map(|mm| mm * 1e-3).ok_or_else(|| self.missing())
    }

    fn missing(&self) -> Error {
        let expected = self.arguments().len();
        let found = usize::from(self.joint.is_some())
            + usize::from(self.harmonics.is_some())
            + usize::from(self.pitch_mm.is_some());
        Error::at_line(
            "--effects",
            1,
            1,
            ErrorKind::EffectList { text: self.to_string(), fault: EffectListFault::Arguments { expected, found } },
        )
    }
}

/// What `--effects` asks for.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum EffectSelection {
    /// These effects (none: the geometry alone, the default).
    List(Vec<EffectSpec>),
    /// What `calib diagnose` selects on the training data.
    #[default]
    None,
    /// `auto`.
    Auto,
}

impl EffectSelection {
    /// The listed effects (empty for `None` and `Auto`).
    pub fn listed(&self) -> &[EffectSpec] {
        match self {
            EffectSelection::List(list) => list,
            _ => &[],
        }
    }
}

impl fmt::Display for EffectSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EffectSelection::None => f.write_str("none"),
            EffectSelection::Auto => f.write_str("auto"),
            EffectSelection::List(list) => {
                let items: Vec<String> = list.iter().map(ToString::to_string).collect();
                f.write_str(&items.join(","))
            }
        }
    }
}

/// The items `--effects` takes, as its refusals list them: every identified kind with its
/// arguments (`joint_compliance, backlash:JOINT, gear_periodic:JOINT:HARMONICS, …`), in the list's
/// order.
pub fn effect_items() -> &'static str {
    static ITEMS: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ITEMS.get_or_init(|| {
        let item = |&kind: &EffectKind| {
            let arguments = IdentifiedEffect::arguments(kind).iter().map(|argument| match argument {
                Argument::Joint => ":JOINT",
                Argument::Harmonics => ":HARMONICS",
                Argument::Pitch => ":PITCH_MM",
            });
            std::iter::once(kind.name()).chain(arguments).collect::<String>()
        };
        EffectKind::IDENTIFIED.iter().map(item).collect::<Vec<_>>().join(", ")
    })
}

fn parse_item(item: &str) -> Result<EffectSpec, EffectListFault> {
    let mut parts = item.split(':');
    let name = parts.next().unwrap_or("").trim();
    let arguments: Vec<&str> = parts.collect();
    let kind = match EffectKind::from_name(name) {
        Some(kind) if kind.is_identified() => kind,
        _ if name.is_empty() => return Err(EffectListFault::Empty { items: effect_items() }),
        _ => return Err(EffectListFault::UnknownEffect { items: effect_items() }),
    };
    let mut spec = EffectSpec::new(kind);
    let expected = spec.arguments();
    if arguments.len() != expected.len() {
        return Err(EffectListFault::Arguments { expected: expected.len(), found: arguments.len() });
    }
    for (argument, text) in expected.iter().zip(arguments) {
        match argument {
            Argument::Joint => match text.trim().parse::<usize>() {
                Ok(j) if j >= 1 => spec.joint = Some(j),
                _ => return Err(EffectListFault::Joint),
            },
            Argument::Harmonics => match text.trim().parse::<u32>() {
                Ok(h) if (1..=MAX_HARMONICS).contains(&h) => spec.harmonics = Some(h),
                _ => return Err(EffectListFault::Harmonics),
            },
            Argument::Pitch => match text.trim().parse::<f64>() {
                Ok(p) if (PITCH_BOUNDS_MM.0..=PITCH_BOUNDS_MM.1).contains(&p) => spec.pitch_mm = Some(p),
                _ => return Err(EffectListFault::Pitch),
            },
        }
    }
    Ok(spec)
}

impl FromStr for EffectSelection {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self, Error> {
        let fault = |offset: usize, item: &str, fault| {
            Error::at_line(
                "--effects",
                1,
                text[..offset].chars().count() + 1,
                ErrorKind::EffectList { text: item.to_owned(), fault },
            )
        };
        if text.trim().is_empty() {
            return Err(fault(0, text, EffectListFault::Empty { items: effect_items() }));
        }
        let mut offset = 0;
        let mut items = Vec::new();
        for item in text.split(',') {
            items.push((offset, item));
            offset += item.len() + 1;
        }
        if items.len() == 1 && items[0].1.trim() == "auto" {
            return Ok(EffectSelection::Auto);
        }
        // What `Display` writes for no effects reads back (a script may pass it on).
        if items.len() == 1 && items[0].1.trim() == "none" {
            return Ok(EffectSelection::None);
        }
        let mut list: Vec<EffectSpec> = Vec::new();
        for (offset, item) in items {
            if item.trim() == "auto" {
                return Err(fault(offset, item, EffectListFault::AutoWithOthers));
            }
            let spec = parse_item(item).map_err(|f| fault(offset, item, f))?;
            if list.iter().any(|s| s.overlaps(&spec)) {
                return Err(fault(offset, item, EffectListFault::Duplicate));
            }
            list.push(spec);
        }
        Ok(EffectSelection::List(list))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fault_of(text: &str) -> (usize, String, EffectListFault) {
        let e = text.parse::<EffectSelection>().expect_err(text);
        match (e.place(), e.kind::<ErrorKind>()) {
            (Some(place), Some(ErrorKind::EffectList { text, fault })) if place.file() == "--effects" => {
                (place.column().expect("a column"), text.clone(), *fault)
            }
            _ => panic!("{text}: {e:?}"),
        }
    }

    #[test]
    fn every_spec_item_parses_and_prints_back() {
        let text = "joint_compliance,gear_periodic:1:24,gear_periodic:2:24,backlash:2,thermal,time_drift";
        let selection: EffectSelection = text.parse().unwrap();
        assert_eq!(
            selection,
            EffectSelection::List(vec![
                EffectSpec::new(EffectKind::JointCompliance),
                EffectSpec::gear_periodic(1, 24),
                EffectSpec::gear_periodic(2, 24),
                EffectSpec::on_joint(EffectKind::Backlash, 2),
                EffectSpec::new(EffectKind::Thermal),
                EffectSpec::new(EffectKind::TimeDrift),
            ])
        );
        assert_eq!(selection.to_string(), text);
        assert_eq!("auto".parse::<EffectSelection>().unwrap(), EffectSelection::Auto);
        assert_eq!("none".parse::<EffectSelection>().unwrap(), EffectSelection::None);
        assert_eq!(EffectSelection::None.to_string().parse::<EffectSelection>().unwrap(), EffectSelection::None);
    }

    #[test]
    fn each_bad_item_is_refused_at_its_column_with_its_fault() {
        assert_eq!(fault_of(""), (1, String::new(), EffectListFault::Empty { items: effect_items() }));
        assert_eq!(
            fault_of("thermal,,time_drift"),
            (9, String::new(), EffectListFault::Empty { items: effect_items() })
        );
        assert_eq!(
            fault_of("thermal,gear:1:3"),
            (9, "gear:1:3".into(), EffectListFault::UnknownEffect { items: effect_items() })
        );
        assert_eq!(
            fault_of("gear_periodic:2"),
            (1, "gear_periodic:2".into(), EffectListFault::Arguments { expected: 2, found: 1 })
        );
        assert_eq!(
            fault_of("thermal:1"),
            (1, "thermal:1".into(), EffectListFault::Arguments { expected: 0, found: 1 })
        );
        assert_eq!(fault_of("backlash:0"), (1, "backlash:0".into(), EffectListFault::Joint));
        assert_eq!(fault_of("backlash:x"), (1, "backlash:x".into(), EffectListFault::Joint));
        assert_eq!(fault_of("gear_periodic:1:0"), (1, "gear_periodic:1:0".into(), EffectListFault::Harmonics));
        assert_eq!(
            fault_of("gear_periodic:1:99999999999"),
            (1, "gear_periodic:1:99999999999".into(), EffectListFault::Harmonics)
        );
        assert_eq!(
            fault_of("gear_periodic:1:3,gear_periodic:1:5"),
            (19, "gear_periodic:1:5".into(), EffectListFault::Duplicate)
        );
        assert_eq!(fault_of("thermal,auto"), (9, "auto".into(), EffectListFault::AutoWithOthers));
        // A screw's pitch: a number of millimetres within the bounds, the harmonics after it.
        for bad in ["screw_periodic:1:0:4", "screw_periodic:1:x:4", "screw_periodic:1:-5:4", "screw_periodic:1:NaN:4"] {
            assert_eq!(fault_of(bad), (1, bad.into(), EffectListFault::Pitch), "{bad}");
        }
        assert_eq!(
            fault_of("screw_periodic:1:4"),
            (1, "screw_periodic:1:4".into(), EffectListFault::Arguments { expected: 3, found: 2 })
        );
        assert_eq!(fault_of("screw_periodic:1:5:0"), (1, "screw_periodic:1:5:0".into(), EffectListFault::Harmonics));
        let message = "screw_periodic:1:20000:4".parse::<EffectSelection>().unwrap_err().to_string();
        assert!(message.contains("has a pitch that is not a number of millimetres from 0.01 to 10000"), "{message}");
        let screw: EffectSelection = "screw_periodic:1:2.5:8".parse().unwrap();
        assert_eq!(screw.listed()[0].pitch_mm, Some(2.5));
        assert_eq!(screw.to_string(), "screw_periodic:1:2.5:8");
        let message = "thermal,backlash:-1".parse::<EffectSelection>().unwrap_err().to_string();
        assert!(message.starts_with("--effects:1:9: 'backlash:-1'"), "{message}");
    }

    #[test]
    fn different_joints_of_one_effect_are_not_duplicates() {
        let selection: EffectSelection = "backlash:1,backlash:2,gear_periodic:1:3".parse().unwrap();
        assert_eq!(selection.listed().len(), 3);
    }

    #[test]
    fn every_identified_kind_is_an_item_and_no_other_kind_is() {
        for &kind in EffectKind::IDENTIFIED {
            let spec = EffectSpec { kind, joint: Some(2), harmonics: Some(3), pitch_mm: Some(5.0) };
            let text: String = std::iter::once(kind.name().to_owned())
                .chain(spec.arguments().iter().map(|a| match a {
                    Argument::Joint => ":2".to_owned(),
                    Argument::Harmonics => ":3".to_owned(),
                    Argument::Pitch => ":5".to_owned(),
                }))
                .collect();
            let parsed: EffectSelection = text.parse().unwrap();
            assert_eq!(parsed.listed()[0].kind, kind, "{text}");
            assert_eq!(parsed.to_string(), text);
        }
        for &kind in EffectKind::ALL.iter().filter(|k| !k.is_identified()) {
            assert_eq!(fault_of(kind.name()).2, EffectListFault::UnknownEffect { items: effect_items() }, "{kind:?}");
        }
    }

    #[test]
    fn the_refusals_list_every_identified_kind() {
        // The list in the messages is written from the one list of kinds (`errors`, a leaf, knows
        // none), each kind with its arguments.
        assert!(
            effect_items().starts_with("joint_compliance, backlash:JOINT, gear_periodic:JOINT:HARMONICS, "),
            "{}",
            effect_items()
        );
        assert!(effect_items().contains("screw_periodic:JOINT:PITCH_MM:HARMONICS"), "{}", effect_items());
        for fault in
            [EffectListFault::Empty { items: effect_items() }, EffectListFault::UnknownEffect { items: effect_items() }]
        {
            let message = fault.to_string();
            for &kind in EffectKind::IDENTIFIED {
                assert!(message.contains(kind.name()), "{message} lacks {}", kind.name());
            }
        }
    }
}
