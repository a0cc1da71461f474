//! `--effects LIST|auto` (SPEC v2): which non-geometric effects a fit identifies with the
//! geometry. Items are `joint_compliance`, `gear_periodic:JOINT:HARMONICS`, `backlash:JOINT`,
//! `thermal` and `time_drift`, comma separated; joints are 1-based. A bad item is refused with its
//! position in the argument and what is wrong with it.

use errors::Error;
use std::fmt;
use std::str::FromStr;

pub use errors::{EffectListFault, MAX_HARMONICS};

/// One effect of an `--effects` list, as the user names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EffectSpec {
    /// Every joint gives under its torque: measured torques (`tauN_nm`) where the data has them,
    /// the gravity-torque regressors otherwise.
    JointCompliance,
    /// A periodic error of one joint in its own angle: harmonics `1..=harmonics`.
    GearPeriodic {
        /// 1-based joint.
        joint: usize,
        /// Highest harmonic order.
        harmonics: u32,
    },
    /// A dead band of one joint that follows the sign of its torque.
    Backlash {
        /// 1-based joint.
        joint: usize,
    },
    /// Every link grows with `temp_c`.
    Thermal,
    /// The robot's placement drifts linearly with `t_s`.
    TimeDrift,
}

impl EffectSpec {
    /// The 1-based joint the item names, if any.
    pub fn joint(&self) -> Option<usize> {
        match *self {
            EffectSpec::GearPeriodic { joint, .. } | EffectSpec::Backlash { joint } => Some(joint),
            _ => None,
        }
    }

    /// Whether two items fit the same parameters (the same effect on the same joint).
    fn overlaps(&self, other: &EffectSpec) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other) && self.joint() == other.joint()
    }
}

impl fmt::Display for EffectSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            EffectSpec::JointCompliance => f.write_str("joint_compliance"),
            EffectSpec::GearPeriodic { joint, harmonics } => write!(f, "gear_periodic:{joint}:{harmonics}"),
            EffectSpec::Backlash { joint } => write!(f, "backlash:{joint}"),
            EffectSpec::Thermal => f.write_str("thermal"),
            EffectSpec::TimeDrift => f.write_str("time_drift"),
        }
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

fn parse_item(item: &str) -> Result<EffectSpec, EffectListFault> {
    let mut parts = item.split(':');
    let name = parts.next().unwrap_or("");
    let arguments: Vec<&str> = parts.collect();
    let expect = |expected: usize| {
        if arguments.len() == expected {
            Ok(())
        } else {
            Err(EffectListFault::Arguments { expected, found: arguments.len() })
        }
    };
    let joint = |text: &str| match text.trim().parse::<usize>() {
        Ok(j) if j >= 1 => Ok(j),
        _ => Err(EffectListFault::Joint),
    };
    match name.trim() {
        "joint_compliance" => expect(0).map(|()| EffectSpec::JointCompliance),
        "thermal" => expect(0).map(|()| EffectSpec::Thermal),
        "time_drift" => expect(0).map(|()| EffectSpec::TimeDrift),
        "backlash" => {
            expect(1)?;
            Ok(EffectSpec::Backlash { joint: joint(arguments[0])? })
        }
        "gear_periodic" => {
            expect(2)?;
            let joint = joint(arguments[0])?;
            let harmonics = match arguments[1].trim().parse::<u32>() {
                Ok(h) if (1..=MAX_HARMONICS).contains(&h) => h,
                _ => return Err(EffectListFault::Harmonics),
            };
            Ok(EffectSpec::GearPeriodic { joint, harmonics })
        }
        "" => Err(EffectListFault::Empty),
        _ => Err(EffectListFault::UnknownEffect),
    }
}

impl FromStr for EffectSelection {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self, Error> {
        let fault = |offset: usize, item: &str, fault| Error::EffectList {
            column: text[..offset].chars().count() + 1,
            text: item.to_owned(),
            fault,
        };
        if text.trim().is_empty() {
            return Err(fault(0, text, EffectListFault::Empty));
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
        match text.parse::<EffectSelection>() {
            Err(Error::EffectList { column, text, fault }) => (column, text, fault),
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn every_spec_item_parses_and_prints_back() {
        let text = "joint_compliance,gear_periodic:1:24,gear_periodic:2:24,backlash:2,thermal,time_drift";
        let selection: EffectSelection = text.parse().unwrap();
        assert_eq!(
            selection,
            EffectSelection::List(vec![
                EffectSpec::JointCompliance,
                EffectSpec::GearPeriodic { joint: 1, harmonics: 24 },
                EffectSpec::GearPeriodic { joint: 2, harmonics: 24 },
                EffectSpec::Backlash { joint: 2 },
                EffectSpec::Thermal,
                EffectSpec::TimeDrift,
            ])
        );
        assert_eq!(selection.to_string(), text);
        assert_eq!("auto".parse::<EffectSelection>().unwrap(), EffectSelection::Auto);
        assert_eq!("none".parse::<EffectSelection>().unwrap(), EffectSelection::None);
        assert_eq!(EffectSelection::None.to_string().parse::<EffectSelection>().unwrap(), EffectSelection::None);
    }

    #[test]
    fn each_bad_item_is_refused_at_its_column_with_its_fault() {
        assert_eq!(fault_of(""), (1, String::new(), EffectListFault::Empty));
        assert_eq!(fault_of("thermal,,time_drift"), (9, String::new(), EffectListFault::Empty));
        assert_eq!(fault_of("thermal,gear:1:3"), (9, "gear:1:3".into(), EffectListFault::UnknownEffect));
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
        let message = "thermal,backlash:-1".parse::<EffectSelection>().unwrap_err().to_string();
        assert!(message.starts_with("--effects:1:9: 'backlash:-1'"), "{message}");
    }

    #[test]
    fn different_joints_of_one_effect_are_not_duplicates() {
        let selection: EffectSelection = "backlash:1,backlash:2,gear_periodic:1:3".parse().unwrap();
        assert_eq!(selection.listed().len(), 3);
    }
}
