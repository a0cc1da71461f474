//! The data bound to a model once: a measurement set whose joints have been checked against the
//! model's (or the robot's) and whose rows each carry the model's index of their tool. Every
//! function that applies a model to rows takes this one value, not the rows and a slice of tool
//! indices beside them, so the tools are mapped and the joints checked once per command.

use crate::ErrorKind;
use crate::{Measurement, MeasurementSet};
use errors::Error;
use poe::JointKind;
use std::borrow::Cow;

/// The index of tool `name` among a model's `tools`; an identifier the model was not fitted with
/// is refused at `file`, `line`, `column` with the tools it knows.
pub fn model_tool(tools: &[String], name: &str, file: &str, line: u64, column: usize) -> Result<usize, Error> {
    tools.iter().position(|t| t == name).ok_or_else(|| {
        Error::at_line(
            file.to_owned(),
            line,
            column,
            ErrorKind::UnknownTool { tool: name.to_owned(), known: tools.to_vec() },
        )
    })
}

/// A measurement set bound to a model: its joint columns checked against the model's joints and
/// each row's tool mapped to the model's tool index, by one constructor, once.
///
/// - [`BoundSet::to_model`]: rows read from a file, for a fitted model (`eval`, `predict`,
///   `register`, `compensate`, the report): the tools matched by identifier, an unknown one
///   refused at its line and the `tool` column.
/// - [`BoundSet::to_robot`]: the rows a fit starts from: the set's tools become the model's, so
///   each row's tool is its own index.
/// - [`BoundSet::made_for_model`]: rows made in memory from a model, their `tool` already its
///   index (a pose to reach, the model check's probe rows).
///
/// The set is borrowed where the caller keeps it and owned where it was made here
/// ([`BoundSet::subset`]).
///
/// ```
/// use measurements::{BoundSet, ReadOptions, parse_measurements};
/// use poe::JointKind;
/// let csv = "q1_rad,x_mm,y_mm,z_mm,tool\n0.1,1000,0,500,probe\n0.2,990,12,510,\n";
/// let data = parse_measurements(csv.as_bytes(), "poses.csv", &ReadOptions::default())?;
/// let joints = [JointKind::Revolute];
/// // The model knows the default tool first, then `probe`.
/// let model_tools = ["".to_owned(), "probe".to_owned()];
/// let bound = BoundSet::to_model(&data, &joints, &model_tools)?;
/// assert_eq!(bound.tools(), &[1, 0]);
/// assert_eq!(bound.iter().map(|(row, tool)| (row.line, tool)).collect::<Vec<_>>(), [(2, 1), (3, 0)]);
/// // A tool the model was not fitted with is refused at its line and the `tool` column.
/// let error = BoundSet::to_model(&data, &joints, &model_tools[..1]).unwrap_err();
/// assert!(error.to_string().starts_with("poses.csv:2:5:"), "{error}");
/// // So are joints the model does not have.
/// let error = BoundSet::to_model(&data, &[JointKind::Revolute; 2], &model_tools).unwrap_err();
/// assert!(error.to_string().starts_with("poses.csv:1:1:"), "{error}");
/// # Ok::<(), errors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BoundSet<'a> {
    set: Cow<'a, MeasurementSet>,
    /// Each row's model tool index, one per row.
    tools: Vec<usize>,
}

impl<'a> BoundSet<'a> {
    /// `set` bound to a model with joints `joints` and tool identifiers `tools` (in the model's
    /// order): the joint columns' count and units are checked
    /// ([`MeasurementSet::check_joints`]) and each row's tool is found by identifier. `""` is the
    /// default tool, matched like any other name (SPEC v2); an identifier the model was not
    /// fitted with is refused at the row's line and the `tool` column (column 1 without one).
    pub fn to_model(
        set: impl Into<Cow<'a, MeasurementSet>>,
        joints: &[JointKind],
        tools: &[String],
    ) -> Result<Self, Error> {
        let set = set.into();
        set.check_joints(joints)?;
        let column = set.tool_column.unwrap_or(1);
        let indices = set
            .rows
            .iter()
            .map(|row| {
                let name = set.tools.get(row.tool).map(String::as_str).unwrap_or("");
                model_tool(tools, name, &set.source, row.line, column)
            })
            .collect::<Result<Vec<usize>, Error>>()?;
        Ok(Self { set, tools: indices })
    }

    /// `set` bound to the robot a fit starts from, with joints `joints` (checked as by
    /// [`BoundSet::to_model`]): the model the fit makes takes the set's tools in their order, so
    /// each row's tool index is its own [`Measurement::tool`].
    pub fn to_robot(set: impl Into<Cow<'a, MeasurementSet>>, joints: &[JointKind]) -> Result<Self, Error> {
        let set = set.into();
        set.check_joints(joints)?;
        let tools = set.rows.iter().map(|r| r.tool).collect();
        Ok(Self { set, tools })
    }

    /// Rows made in memory from a model (a pose it is to reach, a probe of its parts), whose
    /// [`Measurement::tool`] is already the model's tool index: nothing is checked, since the
    /// caller made them from the model; `source` names them in messages.
    pub fn made_for_model(source: &str, rows: Vec<Measurement>) -> BoundSet<'static> {
        let tools = rows.iter().map(|r| r.tool).collect();
        BoundSet { set: Cow::Owned(MeasurementSet::from_rows(source, rows, Vec::new())), tools }
    }

    /// The measurement set as read (its own tool identifiers, file format, source).
    pub fn set(&self) -> &MeasurementSet {
        &self.set
    }

    /// The rows, in file order.
    pub fn rows(&self) -> &[Measurement] {
        &self.set.rows
    }

    /// Each row's model tool index, in the order of [`BoundSet::rows`].
    pub fn tools(&self) -> &[usize] {
        &self.tools
    }

    /// Each row with its model tool index.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (&Measurement, usize)> + '_ {
        self.set.rows.iter().zip(self.tools.iter().copied())
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.set.rows.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.set.rows.is_empty()
    }

    /// These rows without the gross `outliers` an identification of them named (by row, as
    /// [`crate::without`]), bound as these are.
    pub fn without(&self, outliers: &[poe::identify::OutlierRow]) -> BoundSet<'static> {
        let named: std::collections::HashSet<usize> = outliers.iter().map(|o| o.observation).collect();
        let kept: Vec<usize> = (0..self.len()).filter(|i| !named.contains(i)).collect();
        self.subset(&kept)
    }

    /// The rows at `indices`, bound as these are (same model tools; nothing checked again).
    pub fn subset(&self, indices: &[usize]) -> BoundSet<'static> {
        BoundSet { set: Cow::Owned(self.set.subset(indices)), tools: indices.iter().map(|&i| self.tools[i]).collect() }
    }
}

/// A set the caller keeps, borrowed by [`BoundSet::to_model`] and [`BoundSet::to_robot`].
impl<'a> From<&'a MeasurementSet> for Cow<'a, MeasurementSet> {
    fn from(set: &'a MeasurementSet) -> Self {
        Cow::Borrowed(set)
    }
}

/// A set handed over, owned by the [`BoundSet`] made of it.
impl From<MeasurementSet> for Cow<'_, MeasurementSet> {
    fn from(set: MeasurementSet) -> Self {
        Cow::Owned(set)
    }
}

#[cfg(test)]
mod tests {
    use super::BoundSet;
    use crate::ErrorKind;
    use crate::{Measurement, ReadOptions, parse_measurements};
    use lie::Vector3;
    use poe::JointKind;

    const REVOLUTE: [JointKind; 2] = [JointKind::Revolute; 2];

    fn read(csv: &str) -> crate::MeasurementSet {
        parse_measurements(csv.as_bytes(), "poses.csv", &ReadOptions::default()).unwrap()
    }

    fn names(tools: &[&str]) -> Vec<String> {
        tools.iter().map(|t| (*t).to_owned()).collect()
    }

    #[test]
    fn tools_are_matched_by_name_whatever_order_the_file_meets_them() {
        let data = read("q1_rad,q2_rad,x_mm,y_mm,z_mm,tool\n0,0,1,0,0,B\n0,0,1,0,0,\n0,0,1,0,0,B\n0,0,1,0,0,A\n");
        let bound = BoundSet::to_model(&data, &REVOLUTE, &names(&["A", "", "B"])).unwrap();
        assert_eq!(bound.tools(), &[2, 1, 2, 0]);
        assert_eq!(bound.len(), 4);
    }

    #[test]
    fn an_unknown_tool_is_refused_at_its_line_and_the_tool_column() {
        let data = read("tool,q1_rad,q2_rad,x_mm,y_mm,z_mm\nA,0,0,1,0,0\nZ,0,0,1,0,0\n");
        let error = BoundSet::to_model(&data, &REVOLUTE, &names(&["A"])).unwrap_err();
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::UnknownTool { tool, .. }) if tool == "Z"),
            "{error}"
        );
        assert_eq!(error.position(), Some((3, 1)));
        assert!(error.to_string().starts_with("poses.csv:3:1:"), "{error}");
    }

    #[test]
    fn joints_are_checked_by_count_and_by_unit() {
        let data = read("q1_rad,q2_mm,x_mm,y_mm,z_mm\n0,0,1,0,0\n");
        let count = BoundSet::to_robot(&data, &[JointKind::Revolute; 3]).unwrap_err();
        assert!(
            matches!(count.kind::<ErrorKind>(), Some(ErrorKind::JointCountMismatch { found: 2, expected: 3 })),
            "{count}"
        );
        let unit = BoundSet::to_model(&data, &REVOLUTE, &names(&[""])).unwrap_err();
        assert!(matches!(unit.kind::<ErrorKind>(), Some(ErrorKind::JointUnit { joint: 2, .. })), "{unit}");
        assert_eq!(unit.position(), Some((1, 2)));
        assert!(BoundSet::to_robot(&data, &[JointKind::Revolute, JointKind::Prismatic]).is_ok());
    }

    #[test]
    fn a_fit_s_binding_keeps_each_row_s_own_tool() {
        let data = read("q1_rad,q2_rad,x_mm,y_mm,z_mm,tool\n0,0,1,0,0,B\n0,0,1,0,0,A\n0,0,1,0,0,B\n");
        let bound = BoundSet::to_robot(data.clone(), &REVOLUTE).unwrap();
        assert_eq!(bound.tools(), &[0, 1, 0]);
        assert_eq!(bound.set(), &data);
    }

    #[test]
    fn a_subset_keeps_the_model_tools_of_its_rows() {
        let data = read("q1_rad,q2_rad,x_mm,y_mm,z_mm,tool\n0,0,1,0,0,B\n0,0,1,0,0,A\n0,0,1,0,0,B\n");
        let bound = BoundSet::to_model(&data, &REVOLUTE, &names(&["A", "B"])).unwrap();
        let part = bound.subset(&[2, 1]);
        assert_eq!(part.tools(), &[1, 0]);
        assert_eq!(part.rows().iter().map(|r| r.line).collect::<Vec<_>>(), [4, 3]);
        let outlier = poe::identify::OutlierRow {
            observation: 1,
            position_m: 1.0,
            position_sigmas: 100.0,
            rotation_rad: None,
            rotation_sigmas: None,
        };
        let kept = bound.without(&[outlier]);
        assert_eq!((kept.tools(), kept.rows()[1].line), (&[1, 1][..], 4));
    }

    #[test]
    fn rows_made_for_a_model_keep_their_tool_index() {
        let rows = (0..3).map(|k| Measurement { tool: k, ..Measurement::at(vec![0.0; 2], Vector3::zeros()) });
        let bound = BoundSet::made_for_model("probe", rows.collect());
        assert_eq!(bound.tools(), &[0, 1, 2]);
        assert_eq!(bound.set().source, "probe");
        assert_eq!(bound.iter().map(|(_, t)| t).collect::<Vec<_>>(), [0, 1, 2]);
    }
}
