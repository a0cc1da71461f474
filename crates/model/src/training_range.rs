//! The range of every input a model was fitted on, recorded in the model file: the
//! check on reading walks the parts at rows inside it, where a sound model is sound, instead of at
//! joint values it may never have seen (every joint at 1 rad refused a sound GP fitted with the
//! wrist held within 2 mrad of zero). Model files written before it existed have none and read.

use measurements::Measurement;
use serde::{Deserialize, Serialize};

/// Smallest and largest value of each input over the training rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingRange {
    /// Per joint, `[min, max]` (radians or metres).
    pub q: Vec<[f64; 2]>,
    /// `[min, max]` of the payload, kg.
    pub payload_kg: [f64; 2],
    /// `[min, max]` of the temperature, °C, where every row had one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temp_c: Option<[f64; 2]>,
    /// `[min, max]` of the time, s, where every row had one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_s: Option<[f64; 2]>,
    /// Per joint, `[min, max]` of the measured torque, N·m, where every row had them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torques_nm: Option<Vec<[f64; 2]>>,
    /// The measured signals the model takes as inputs (`--inputs`), each with its
    /// unit and `[min, max]` over the training rows, in the order the model takes them. Absent
    /// in files written before there were inputs, and for models that take none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<InputSpan>,
}

/// A measured signal a model takes as an input, as fitted: `calib eval`, `predict`, `compensate`
/// and `report` require its column by name and count the rows outside its span.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpan {
    /// The column's name (after `--columns`).
    pub name: String,
    /// The unit its name's suffix states ([`measurements::input_unit`]), if any.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "crate::unit_name::input")]
    pub unit: Option<crate::unit_name::Unit>,
    /// Its smallest and largest value on the training rows.
    pub fitted: [f64; 2],
}

impl std::fmt::Display for InputSpan {
    /// `tilt_x_mrad: -1.2 … 3.4 mrad`, the numbers as written (shortest round trip).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [low, high] = self.fitted;
        write!(f, "{}: {low} … {high}", self.name)?;
        match self.unit {
            Some(unit) => write!(f, " {unit}"),
            None => Ok(()),
        }
    }
}

fn span(values: impl Iterator<Item = f64>) -> [f64; 2] {
    values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| [lo.min(v), hi.max(v)])
}

fn spans<'a>(rows: impl Iterator<Item = &'a [f64]> + Clone, n: usize) -> Vec<[f64; 2]> {
    (0..n).map(|j| span(rows.clone().map(|r| r[j]))).collect()
}

impl TrainingRange {
    /// The ranges of `rows` (`None` for no rows); optional inputs only where every row has them,
    /// measured signals ([`Measurement::inputs`]) those of the first row that every row has.
    pub fn of(rows: &[Measurement]) -> Option<Self> {
        let first = rows.first()?;
        let n = first.q.len();
        let inputs = first
            .inputs
            .names()
            .iter()
            .enumerate()
            .filter_map(|(k, name)| {
                let values: Option<Vec<f64>> = rows.iter().map(|r| r.inputs.value(k, name)).collect();
                let fitted = span(values?.into_iter());
                Some(InputSpan { name: name.clone(), unit: measurements::input_unit(name), fitted })
            })
            .collect();
        let all = |f: fn(&Measurement) -> Option<f64>| rows.iter().map(f).collect::<Option<Vec<f64>>>();
        let torques: Option<Vec<&[f64]>> =
            rows.iter().map(|r| r.torques_nm.as_deref().filter(|t| t.len() == n)).collect();
        Some(Self {
            q: spans(rows.iter().map(|r| r.q.as_slice()), n),
            payload_kg: span(rows.iter().map(|r| r.payload_kg)),
            temp_c: all(|r| r.temp_c).map(|v| span(v.into_iter())),
            t_s: all(|r| r.t_s).map(|v| span(v.into_iter())),
            torques_nm: torques.map(|t| spans(t.into_iter(), n)),
            inputs,
        })
    }

    /// The span of input `name`, if the range records it.
    pub fn input(&self, name: &str) -> Option<&InputSpan> {
        self.inputs.iter().find(|i| i.name == name)
    }

    /// The first range that is not finite, reversed, of the wrong length, or (for a joint)
    /// beyond `limit`: its field name, index and the offending value.
    pub(crate) fn fault(&self, joints: usize, limit: f64) -> Option<(&'static str, usize, f64)> {
        if self.q.len() != joints {
            return Some(("q", self.q.len(), self.q.len() as f64));
        }
        if let Some(t) = &self.torques_nm
            && t.len() != joints
        {
            return Some(("torques_nm", t.len(), t.len() as f64));
        }
        let bad = |r: &[f64; 2], bound: f64| {
            r.iter().copied().find(|v| !v.is_finite() || v.abs() > bound).or((r[0] > r[1]).then_some(r[0]))
        };
        let lists: [(&'static str, &[[f64; 2]], f64); 2] =
            [("q", &self.q, limit), ("torques_nm", self.torques_nm.as_deref().unwrap_or(&[]), f64::MAX)];
        for (name, list, bound) in lists {
            if let Some((k, v)) = list.iter().enumerate().find_map(|(k, r)| bad(r, bound).map(|v| (k, v))) {
                return Some((name, k, v));
            }
        }
        let single = [("payload_kg", Some(self.payload_kg)), ("temp_c", self.temp_c), ("t_s", self.t_s)];
        if let Some(fault) =
            single.into_iter().find_map(|(name, r)| r.and_then(|r| bad(&r, f64::MAX)).map(|v| (name, 0, v)))
        {
            return Some(fault);
        }
        self.inputs.iter().enumerate().find_map(|(k, i)| bad(&i.fitted, f64::MAX).map(|v| ("inputs", k, v)))
    }

    /// Rows inside the ranges at which a model is probed: the centre of every range, and the
    /// corners where every input is at its smallest and at its largest (tool 0, no measured pose).
    pub(crate) fn probe_rows(&self) -> Vec<Measurement> {
        let names: std::sync::Arc<[String]> = self.inputs.iter().map(|i| i.name.clone()).collect();
        let at = |pick: fn(&[f64; 2]) -> f64| Measurement {
            inputs: measurements::Inputs::new(names.clone(), self.inputs.iter().map(|i| pick(&i.fitted)).collect()),
            payload_kg: pick(&self.payload_kg),
            temp_c: Some(self.temp_c.as_ref().map_or(0.0, pick)),
            t_s: Some(self.t_s.as_ref().map_or(0.0, pick)),
            torques_nm: Some(match &self.torques_nm {
                Some(t) => t.iter().map(pick).collect(),
                None => vec![0.0; self.q.len()],
            }),
            ..Measurement::at(self.q.iter().map(pick).collect(), lie::Vector3::zeros())
        };
        vec![at(|r| 0.5 * (r[0] + r[1])), at(|r| r[0]), at(|r| r[1])]
    }
}

/// Rows that put an input outside the range the model was fitted on: there every part of the
/// model (geometry, effects, GP) answers for poses it never saw, and its error is not what the
/// fit measured. One per input that some row leaves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutOfRangeWarning {
    /// The input: `joint 3`, `payload_kg`, `temp_c`, `t_s`, or a measured signal by its name.
    pub input: String,
    /// Its unit: `rad`, `m` (a prismatic joint), `kg`, `°C`, `s`; a signal's as its name states
    /// it, empty where the name states none.
    #[serde(deserialize_with = "crate::unit_name::deserialize")]
    pub unit: crate::unit_name::Unit,
    /// Its smallest and largest value on the training rows.
    pub fitted: [f64; 2],
    /// How many rows lie outside.
    pub rows_outside: usize,
    /// How many rows there are.
    pub rows: usize,
    /// The file line of the first of them.
    pub first_line: u64,
}

impl std::fmt::Display for OutOfRangeWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [low, high] = self.fitted;
        write!(
            f,
            "{} of {} rows (the first at line {}) put {} outside the range the model was fitted on \
             ({low:.4} … {high:.4}{}{}): there the model answers for inputs it never saw",
            self.rows_outside,
            self.rows,
            self.first_line,
            self.input,
            if self.unit.is_empty() { "" } else { " " },
            self.unit
        )
    }
}

impl TrainingRange {
    /// Whether every joint of `row` lies within the range.
    pub fn contains_joints(&self, row: &Measurement) -> bool {
        self.q.iter().zip(&row.q).all(|(&[low, high], &q)| (low..=high).contains(&q))
    }

    /// Whether every input of `row` (joints, payload, and temperature and time where the range
    /// records them) lies within the range.
    pub fn contains(&self, row: &Measurement) -> bool {
        let within = |v: f64, [low, high]: [f64; 2]| (low..=high).contains(&v);
        self.q.iter().zip(&row.q).all(|(&range, &q)| within(q, range))
            && within(row.payload_kg, self.payload_kg)
            && self.temp_c.zip(row.temp_c).is_none_or(|(range, v)| within(v, range))
            && self.t_s.zip(row.t_s).is_none_or(|(range, v)| within(v, range))
            && self
                .inputs
                .iter()
                .enumerate()
                .all(|(k, i)| row.inputs.value(k, &i.name).is_none_or(|v| within(v, i.fitted)))
    }

    /// One warning per input that some of `rows` put outside its fitted range (`prismatic[j]`:
    /// whether joint `j` is prismatic, for its unit).
    pub fn outside(&self, rows: &[Measurement], prismatic: &[bool]) -> Vec<OutOfRangeWarning> {
        type Pick<'a> = Box<dyn Fn(&Measurement) -> Option<f64> + 'a>;
        let mut inputs: Vec<(String, &'static str, [f64; 2], Pick<'_>)> = self
            .q
            .iter()
            .enumerate()
            .map(|(j, &range)| {
                let unit = if prismatic.get(j).copied().unwrap_or(false) { "m" } else { "rad" };
                (
                    format!("joint {}", j + 1),
                    unit,
                    range,
                    Box::new(move |r: &Measurement| r.q.get(j).copied()) as Pick<'_>,
                )
            })
            .collect();
        inputs.push(("payload_kg".into(), "kg", self.payload_kg, Box::new(|r: &Measurement| Some(r.payload_kg))));
        if let Some(range) = self.temp_c {
            inputs.push(("temp_c".into(), "°C", range, Box::new(|r: &Measurement| r.temp_c)));
        }
        if let Some(range) = self.t_s {
            inputs.push(("t_s".into(), "s", range, Box::new(|r: &Measurement| r.t_s)));
        }
        for (k, input) in self.inputs.iter().enumerate() {
            let name = input.name.as_str();
            let pick = Box::new(move |r: &Measurement| r.inputs.value(k, name)) as Pick<'_>;
            inputs.push((input.name.clone(), input.unit.unwrap_or(""), input.fitted, pick));
        }
        inputs
            .into_iter()
            .filter_map(|(input, unit, fitted, pick)| {
                let [low, high] = fitted;
                let outside: Vec<&Measurement> =
                    rows.iter().filter(|r| pick(r).is_some_and(|v| v < low || v > high)).collect();
                let first = outside.first()?;
                Some(OutOfRangeWarning {
                    input,
                    unit,
                    fitted,
                    rows_outside: outside.len(),
                    rows: rows.len(),
                    first_line: first.line,
                })
            })
            .collect()
    }
}
