//! The quantities the SPEC's column names stand for, with the factor from their unit to SI.

use poe::JointKind;

/// A quantity the SPEC names, with the factor that turns its unit into SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Quantity {
    /// `q<k>_rad|deg|m|mm`: joint `k` (1-based; `usize::MAX` when the digits overflow).
    Joint {
        index: usize,
        kind: JointKind,
        scale: f64,
    },
    /// `x_mm`, `y_m`, …: axis 0, 1, 2.
    Position {
        axis: usize,
        scale: f64,
    },
    /// `qw`, `qx`, `qy`, `qz`: component 0…3.
    Quaternion(usize),
    /// `rx_deg`, `ry_rad`, …: axis 0, 1, 2 (SPEC v2).
    Euler {
        axis: usize,
        scale: f64,
    },
    Payload,
    Tool,
    Temperature,
    Time,
    /// `tau<k>_nm`.
    Torque(usize),
    /// `std_x_mm`, `std_y_m`, …: the tracker's stated standard deviation of position axis 0, 1, 2.
    PositionStd {
        axis: usize,
        scale: f64,
    },
    /// `std_rx_mrad`, `std_ry_deg`, `std_rz_rad`: the stated standard deviation of the orientation
    /// about axis 0, 1, 2.
    RotationStd {
        axis: usize,
        scale: f64,
    },
}

/// `q3_rad` → `Some((3, "rad"))` for the prefix `q`. Digits too many for a `usize` give
/// `usize::MAX`, so that the header check refuses the column rather than ignoring it.
fn indexed_name<'a>(name: &'a str, prefix: &str) -> Option<(usize, &'a str)> {
    let rest = name.strip_prefix(prefix)?;
    let (digits, unit) = rest.split_once('_')?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) || digits.starts_with('0') {
        return None;
    }
    Some((digits.parse().unwrap_or(usize::MAX), unit))
}

/// `x_mm` … `rz_mrad` after `std_`: a stated standard deviation of a position or an orientation
/// axis, with its unit's factor to SI.
fn stated_std(rest: &str) -> Option<Quantity> {
    let (axis, unit) = rest.split_once('_')?;
    let position =
        |scale| ["x", "y", "z"].iter().position(|a| *a == axis).map(|axis| Quantity::PositionStd { axis, scale });
    let rotation =
        |scale| ["rx", "ry", "rz"].iter().position(|a| *a == axis).map(|axis| Quantity::RotationStd { axis, scale });
    match unit {
        "mm" => position(1e-3),
        "m" => position(1.0),
        "um" => position(1e-6),
        "mrad" => rotation(1e-3),
        "rad" => rotation(1.0),
        "deg" => rotation(1f64.to_radians()),
        _ => None,
    }
}

/// The quantity a SPEC column name stands for; `None` for any other name.
pub(crate) fn quantity(name: &str) -> Option<Quantity> {
    let axis = |c: u8| (c - b'x') as usize;
    Some(match name {
        "x_mm" | "y_mm" | "z_mm" => Quantity::Position { axis: axis(name.as_bytes()[0]), scale: 1e-3 },
        "x_m" | "y_m" | "z_m" => Quantity::Position { axis: axis(name.as_bytes()[0]), scale: 1.0 },
        "qw" => Quantity::Quaternion(0),
        "qx" | "qy" | "qz" => Quantity::Quaternion(1 + axis(name.as_bytes()[1])),
        "rx_deg" | "ry_deg" | "rz_deg" => Quantity::Euler { axis: axis(name.as_bytes()[1]), scale: 1f64.to_radians() },
        "rx_rad" | "ry_rad" | "rz_rad" => Quantity::Euler { axis: axis(name.as_bytes()[1]), scale: 1.0 },
        "payload_kg" => Quantity::Payload,
        "tool" => Quantity::Tool,
        "temp_c" => Quantity::Temperature,
        "t_s" => Quantity::Time,
        _ if name.starts_with("std_") => return stated_std(&name[4..]),
        _ => {
            if let Some((index, unit)) = indexed_name(name, "q") {
                let (kind, scale) = match unit {
                    "rad" => (JointKind::Revolute, 1.0),
                    "deg" => (JointKind::Revolute, 1f64.to_radians()),
                    "m" => (JointKind::Prismatic, 1.0),
                    "mm" => (JointKind::Prismatic, 1e-3),
                    _ => return None,
                };
                Quantity::Joint { index, kind, scale }
            } else {
                match indexed_name(name, "tau") {
                    Some((index, "nm")) => Quantity::Torque(index),
                    _ => return None,
                }
            }
        }
    })
}
