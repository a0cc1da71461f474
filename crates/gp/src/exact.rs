//! The exact GP model: fitting (hyperparameter search, factorisation with jitter) and the stored
//! form it is serialised to.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::cholesky::{Factor, JitterOutcome};
use crate::config::{GpConfig, OutputMode, Parallelism};
use crate::gram::training_covariance;
use crate::kernel::{Bounds, KernelChoice};
use crate::kernel::{Evaluator, Kernel, Prepared};
use crate::lml::check_finite_outputs;
use crate::optimise::ExpectedGroups;
use crate::optimise::{OptimisationReport, WarmStage, finish_from, refine, warm_stage_from};
use crate::points::Points;
use crate::scaling::{InputStandardiser, OutputNormaliser};

/// An exact Gaussian process fitted to `n` points with `d` inputs and `m` outputs.
///
/// Inputs are standardised and outputs normalised as the [`GpConfig`] said; the maps are stored and
/// applied again in [`ExactGp::predict`]. Serialises (serde) to its training data, the scaling maps
/// and the fit report; the factorisation is rebuilt, with the recorded jitter, when it is read back.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "StoredExactGp", into = "StoredExactGp")]
pub struct ExactGp {
    pub(crate) inputs: InputStandardiser,
    pub(crate) outputs: OutputNormaliser,
    /// Standardised training inputs.
    pub(crate) x: Points,
    /// Normalised training outputs, `n × m`.
    pub(crate) y: Mat<f64>,
    pub(crate) components: Vec<Component>,
    pub(crate) parallelism: Parallelism,
    pub(crate) report: ExactFitReport,
}

/// One kernel with its factorisation and the outputs it serves.
#[derive(Debug, Clone)]
pub(crate) struct Component {
    pub(crate) kernel: Kernel,
    pub(crate) outputs: Vec<usize>,
    pub(crate) evaluator: Evaluator,
    /// Training inputs prepared for `evaluator`.
    pub(crate) prepared: Prepared,
    pub(crate) factor: Factor,
    /// `(K + σn² I + jitter I)⁻¹ y` for each served output (R&W Algorithm 2.1, line 3).
    pub(crate) alpha: Mat<f64>,
}

/// What the exact GP's fit did, per kernel (the sparse GP's: [`crate::SparseFitReport`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactFitReport {
    /// One entry per kernel: one per output ([`OutputMode::Independent`]) or one for all
    /// ([`OutputMode::Shared`]).
    pub components: Vec<ComponentReport>,
}

/// The fit of one kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComponentReport {
    /// Output columns this kernel models.
    pub outputs: Vec<usize>,
    /// Hyperparameters, for standardised inputs and normalised outputs.
    pub kernel: Kernel,
    /// Log marginal likelihood of the normalised outputs it serves, summed over them, with the
    /// jitter (if any) included in the covariance.
    pub log_marginal_likelihood: f64,
    /// Jitter added to make the final factorisation succeed.
    pub jitter: JitterOutcome,
    /// The hyperparameter search (`None` when the hyperparameters were given).
    pub optimisation: Option<OptimisationReport>,
    /// The choice between the kernel and its form without the additive term
    /// ([`GpConfig::additive_by_bic`]; `None` when it was not made).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub additive_choice: Option<AdditiveChoice>,
    /// The choice between the searched kernel and the paper's isotropic Eq. 5 kernel
    /// ([`GpConfig::isotropic_by_loo`]; `None` when it was not made, as in files written before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub isotropic_choice: Option<IsotropicChoice>,
}

/// The leave-one-out choice between the searched kernel and the paper's isotropic Eq. 5 kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IsotropicChoice {
    /// Leave-one-out log predictive probability (R&W Eq. 5.11, normalised outputs, summed over the
    /// rows and the outputs served) of the searched kernel.
    pub searched: f64,
    /// The same for the isotropic Eq. 5 kernel, at the hyperparameters it was compared with.
    pub isotropic: f64,
    /// Whether the isotropic kernel was kept (`isotropic > searched`).
    pub kept_isotropic: bool,
    /// Rows on which the isotropic kernel's hyperparameters compared above were searched: the
    /// warm-start subset where the comparison there already lost, else all rows.
    pub isotropic_search_rows: usize,
    /// Rows the two leave-one-out sums above were computed on: the warm-start subset where the
    /// isotropic kernel, searched there, predicted those rows no better than the searched kernel
    /// (and was not compared on all rows); `None`: all rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compared_rows: Option<usize>,
}

/// The Schwarz (BIC) choice between a kernel with an additive term and the same kernel without.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdditiveChoice {
    /// Log marginal likelihood reached with the additive term.
    pub with_additive: f64,
    /// Log marginal likelihood reached without it.
    pub without_additive: f64,
    /// `½ k ln N`: `k` the additive term's hyperparameters, `N` the observed values the two
    /// likelihoods were computed on (`rows` times the outputs served).
    pub penalty: f64,
    /// Whether the additive term was kept (`with − without > penalty`).
    pub kept: bool,
    /// Rows the two likelihoods were computed on: the warm-start subset when the search has one
    /// (the choice is made there, and only the chosen kernel is searched on all rows), else all.
    pub rows: usize,
}

/// `(a(), b())`, side by side on the rayon pool or one after the other.
fn both<T: Send>(parallelism: Parallelism, a: impl FnOnce() -> T + Send, b: impl FnOnce() -> T + Send) -> (T, T) {
    match parallelism {
        Parallelism::Sequential => (a(), b()),
        Parallelism::Rayon => rayon::join(a, b),
    }
}

enum Hyperparameters<'a> {
    Optimise(&'a Kernel),
    Fixed(&'a [Kernel]),
}

/// A kernel with its factorisation, and what its fit did.
type Fitted = (Component, ComponentReport);

/// The output groups searched (one per output, or one for all), and the follower groups that are
/// fitted from the searched kernel that explains them best (searched hyperparameters and
/// independent outputs only).
fn output_groups(how: &Hyperparameters<'_>, config: &GpConfig, m: usize) -> Result<[Vec<Vec<usize>>; 2], Error> {
    let followers: Vec<Vec<usize>> =
        if matches!(how, Hyperparameters::Optimise(_)) && config.outputs == OutputMode::Independent {
            config.follower_groups.clone()
        } else {
            Vec::new()
        };
    let mut follows = vec![false; m];
    for &j in followers.iter().flatten() {
        if j >= m || follows[j] {
            return Err(Error::InvalidConfig { field: "follower_groups", value: j as f64 });
        }
        follows[j] = true;
    }
    if followers.iter().any(Vec::is_empty) || (!followers.is_empty() && follows.iter().all(|f| *f)) {
        return Err(Error::InvalidConfig { field: "follower_groups", value: followers.len() as f64 });
    }
    let groups: Vec<Vec<usize>> = match config.outputs {
        OutputMode::Independent => (0..m).filter(|&j| !follows[j]).map(|j| vec![j]).collect(),
        OutputMode::Shared => vec![(0..m).collect()],
    };
    Ok([groups, followers])
}

/// What every output group's fit reads: the scaled training data, the config, and whether the
/// hyperparameters are searched or given.
struct GroupFits<'a> {
    xs: &'a Points,
    /// Normalised outputs, `n × m`.
    yn: &'a Mat<f64>,
    config: &'a GpConfig,
    how: &'a Hyperparameters<'a>,
}

/// One group of outputs: their columns and their normalised values, `n × cols.len()`.
#[derive(Clone, Copy)]
struct Group<'g> {
    cols: &'g [usize],
    y: MatRef<'g, f64>,
}

impl GroupFits<'_> {
    /// The normalised outputs `cols`, `n × cols.len()`.
    fn outputs(&self, cols: &[usize]) -> Mat<f64> {
        Mat::from_fn(self.yn.nrows(), cols.len(), |i, c| self.yn[(i, cols[c])])
    }

    /// The configured search box, or `kernel`'s default one.
    fn bounds_of(&self, kernel: &Kernel) -> Bounds {
        self.config.bounds.clone().unwrap_or_else(|| kernel.default_bounds())
    }

    /// `start`, then `nested` (its own nested starts unless a fitted smaller model gives better ones).
    fn search(&self, start: &Kernel, nested: &[Kernel], g: Group<'_>) -> Result<(Kernel, OptimisationReport), Error> {
        start.validate(self.xs.dim())?;
        let (bounds, optimiser, par) = (self.bounds_of(start), &self.config.optimiser, self.config.parallelism);
        let warm = warm_stage_from(start, nested, &bounds, self.xs, g.y, optimiser, par)?;
        let o = finish_from(start, nested, &bounds, self.xs, g.y, optimiser, par, warm)?;
        Ok((o.kernel, o.report))
    }

    /// `kernel` factorised on group `g`, with its report.
    fn build(&self, kernel: Kernel, g: Group<'_>, optimisation: Option<OptimisationReport>) -> Result<Fitted, Error> {
        kernel.validate(self.xs.dim())?;
        let config = self.config;
        let (component, jitter) =
            Component::build(kernel.clone(), g.cols.to_vec(), self.xs, g.y, None, config, config.parallelism)?;
        let lml = component.log_marginal_likelihood(g.y);
        let report = ComponentReport {
            outputs: g.cols.to_vec(),
            kernel,
            log_marginal_likelihood: lml,
            jitter,
            optimisation,
            additive_choice: None,
            isotropic_choice: None,
        };
        Ok((component, report))
    }

    /// Group `index` (outputs `cols`) at its given hyperparameters, or searched, with the Schwarz
    /// choice of the additive term where the config asks for it.
    fn fit_searched(&self, index: usize, cols: &[usize]) -> Result<Fitted, Error> {
        let y = self.outputs(cols);
        let g = Group { cols, y: y.as_ref() };
        let start = match self.how {
            Hyperparameters::Fixed(kernels) => {
                return self.build(kernels[index.min(kernels.len() - 1)].clone(), g, None);
            }
            Hyperparameters::Optimise(start) => *start,
        };
        let reduced = if self.config.additive_by_bic { start.without_additive() } else { None };
        let Some(reduced) = reduced else {
            let (kernel, report) = self.search(start, &start.nested_starts(), g)?;
            return self.build(kernel, g, Some(report));
        };
        match self.additive_on_subset(start, &reduced, g)? {
            Some(fitted) => Ok(fitted),
            None => self.additive_on_all_rows(start, &reduced, g),
        }
    }

    /// The Schwarz choice: ½ k ln N for the additive term's k extra hyperparameters (`start`'s
    /// over `reduced`'s) over the N = rows · (outputs served) values the two likelihoods are
    /// computed on.
    fn penalty(start: &Kernel, reduced: &Kernel, served: usize, rows: usize) -> f64 {
        let k = (start.parameter_count() - reduced.parameter_count()) as f64;
        0.5 * k * ((rows * served) as f64).ln()
    }

    /// With a warm-start subset, both kernels are searched there and the choice is made on the
    /// subset's likelihoods; only the chosen kernel is searched on all rows. `None` without a
    /// subset.
    ///
    /// The larger kernel's nested start is the smaller one's subset optimum with the additive term
    /// nearly off ([`Kernel::nested_at`]), searched after it beside the default start: the same
    /// nesting as [`Kernel::nested_starts`] without walking the smaller model's path a second time.
    fn additive_on_subset(&self, start: &Kernel, reduced: &Kernel, g: Group<'_>) -> Result<Option<Fitted>, Error> {
        let (config, xs) = (self.config, self.xs);
        let warm_from = |k: &Kernel, nested: &[Kernel], optimiser: &crate::OptimiserConfig| {
            k.validate(xs.dim())?;
            warm_stage_from(k, nested, &self.bounds_of(k), xs, g.y, optimiser, config.parallelism)
        };
        // Random restarts, when configured, belong to the default start's stage alone.
        let once = crate::OptimiserConfig { restarts: 0, ..config.optimiser.clone() };
        let warm = both(
            config.parallelism,
            || Ok((warm_from(start, &[], &config.optimiser)?, None)),
            || {
                let without = warm_from(reduced, &[], &config.optimiser)?;
                let nested = match &without {
                    Some(stage) => start
                        .nested_at(&stage.best_kernel(reduced)?)
                        .or_else(|| start.nested_starts().into_iter().next()),
                    None => None,
                };
                let nested = match nested {
                    Some(nested) => warm_from(&nested, &[], &once)?,
                    None => None,
                };
                Ok::<_, Error>((without, nested))
            },
        );
        let ((with, _), (without, nested)) = (warm.0?, warm.1?);
        let with = match (with, nested) {
            (Some(with), Some(nested)) => Some(with.join(nested)),
            (with, _) => with,
        };
        let (Some(with), Some(without)) = (with, without) else { return Ok(None) };
        let rows = with.rows();
        let (a, b) = (with.best_log_marginal_likelihood(), without.best_log_marginal_likelihood());
        let penalty = Self::penalty(start, reduced, g.cols.len(), rows);
        let kept = a - b > penalty;
        let choice = AdditiveChoice { with_additive: a, without_additive: b, penalty, kept, rows };
        let (chosen, stage) = if kept { (start, with) } else { (reduced, without) };
        let (bounds, nested) = (self.bounds_of(chosen), chosen.nested_starts());
        let o = finish_from(chosen, &nested, &bounds, xs, g.y, &config.optimiser, config.parallelism, Some(stage))?;
        let (component, mut report) = self.build(o.kernel, g, Some(o.report))?;
        report.additive_choice = Some(choice);
        Ok(Some((component, report)))
    }

    /// Without a subset, the same nesting on all rows: the smaller kernel first, then the larger
    /// one from its default start and from the smaller one's optimum.
    fn additive_on_all_rows(&self, start: &Kernel, reduced: &Kernel, g: Group<'_>) -> Result<Fitted, Error> {
        let n = g.y.nrows();
        let (small_kernel, small_report) = self.search(reduced, &reduced.nested_starts(), g)?;
        let nested = start.nested_at(&small_kernel).map_or_else(|| start.nested_starts(), |k| vec![k]);
        let (full_kernel, full_report) = self.search(start, &nested, g)?;
        let with = self.build(full_kernel, g, Some(full_report))?;
        let without = self.build(small_kernel, g, Some(small_report))?;
        let penalty = Self::penalty(start, reduced, g.cols.len(), n);
        let choice = AdditiveChoice {
            with_additive: with.1.log_marginal_likelihood,
            without_additive: without.1.log_marginal_likelihood,
            penalty,
            kept: with.1.log_marginal_likelihood - without.1.log_marginal_likelihood > penalty,
            rows: n,
        };
        let (component, mut report) = if choice.kept { with } else { without };
        report.additive_choice = Some(choice);
        Ok((component, report))
    }

    /// Leave-one-out log predictive probability (R&W Eq. 5.11), summed over rows and outputs.
    fn loo(&self, c: &Component) -> f64 {
        c.log_predictive(&c.inverse_diagonal(self.config.parallelism.faer())).iter().sum()
    }

    /// The paper's Eq. 5 beside the searched kernel, kept where it predicts the rows it has not
    /// seen better (leave-one-out, R&W Eq. 5.11).
    fn with_isotropic(&self, searched: Fitted, cols: &[usize]) -> Result<Fitted, Error> {
        let (config, xs) = (self.config, self.xs);
        let optimised = matches!(self.how, Hyperparameters::Optimise(_));
        if !config.isotropic_by_loo || !optimised || matches!(searched.1.kernel, Kernel::Quadratic(_)) {
            return Ok(searched);
        }
        let y = self.outputs(cols);
        let g = Group { cols, y: y.as_ref() };
        let start = Kernel::start(KernelChoice::Quadratic, xs.dim());
        let (bounds, nested) = (start.default_bounds(), start.nested_starts());
        let (optimiser, parallelism) = (&config.optimiser, config.parallelism);
        let stage = warm_stage_from(&start, &nested, &bounds, xs, g.y, optimiser, parallelism)?;
        let screened = match &stage {
            Some(stage) => self.isotropic_screen(&searched, stage, &start, g)?,
            None => None,
        };
        if let Some(choice) = screened {
            let (component, mut report) = searched;
            report.isotropic_choice = Some(choice);
            return Ok((component, report));
        }
        let searched_loo = self.loo(&searched.0);
        if let Some(stage) = &stage {
            // The subset's optimum compared on all rows first: a full search only when the
            // isotropic kernel already predicts better from there.
            let at_subset = self.build(stage.best_kernel(&start)?, g, None)?;
            let at_subset_loo = self.loo(&at_subset.0);
            if at_subset_loo <= searched_loo {
                return Ok(choose_isotropic(searched, at_subset, (searched_loo, at_subset_loo), stage.rows()));
            }
        }
        let o = finish_from(&start, &nested, &bounds, xs, g.y, optimiser, parallelism, stage)?;
        let isotropic = self.build(o.kernel, g, Some(o.report))?;
        let isotropic_loo = self.loo(&isotropic.0);
        Ok(choose_isotropic(searched, isotropic, (searched_loo, isotropic_loo), g.y.nrows()))
    }

    /// Screened on the subset first, each kernel's leave-one-out over the subset's own rows: the
    /// isotropic kernel at its subset optimum, fitted to those rows, against the searched kernel
    /// at its all-rows optimum. Where the isotropic kernel predicts the rows it was fitted to no
    /// better, it is not compared on all rows (two factorisations and an inverse of the full
    /// covariance saved): the choice to report, else `None`.
    fn isotropic_screen(
        &self,
        searched: &Fitted,
        stage: &WarmStage,
        start: &Kernel,
        g: Group<'_>,
    ) -> Result<Option<IsotropicChoice>, Error> {
        let (config, idx) = (self.config, stage.indices());
        let sub_x = self.xs.select(idx);
        let sub_y = Mat::from_fn(idx.len(), g.cols.len(), |i, c| g.y[(idx[i], c)]);
        let on_subset = |kernel: Kernel| -> Result<f64, Error> {
            let (c, _) =
                Component::build(kernel, g.cols.to_vec(), &sub_x, sub_y.as_ref(), None, config, config.parallelism)?;
            Ok(self.loo(&c))
        };
        let (sub_searched, sub_isotropic) =
            (on_subset(searched.1.kernel.clone())?, on_subset(stage.best_kernel(start)?)?);
        Ok((sub_isotropic <= sub_searched).then(|| IsotropicChoice {
            searched: sub_searched,
            isotropic: sub_isotropic,
            kept_isotropic: false,
            isotropic_search_rows: stage.rows(),
            compared_rows: Some(stage.rows()),
        }))
    }

    /// A follower group (outputs `cols`) from the fitted kernel among `leaders` that explains it
    /// best, refined on all rows.
    fn follow(&self, leaders: &[Kernel], cols: &[usize]) -> Result<Fitted, Error> {
        let config = self.config;
        let y = self.outputs(cols);
        let g = Group { cols, y: y.as_ref() };
        let mut best: Option<(f64, &Kernel)> = None;
        for kernel in leaders {
            let (component, _) =
                Component::build(kernel.clone(), cols.to_vec(), self.xs, g.y, None, config, config.parallelism)?;
            let lml = component.log_marginal_likelihood(g.y);
            if best.is_none_or(|(b, _)| lml > b) {
                best = Some((lml, kernel));
            }
        }
        let start = best.map(|(_, k)| k).ok_or(Error::OptimisationFailed { starts: 0 })?;
        // The configured box where it is the chosen kernel's (its family may differ: the
        // isotropic kernel or the form without the additive term).
        let bounds = config
            .bounds
            .clone()
            .filter(|b| b.lower.len() == start.parameter_count())
            .unwrap_or_else(|| start.default_bounds());
        let o = refine(start, &bounds, self.xs, g.y, &config.optimiser, config.parallelism)?;
        self.with_isotropic(self.build(o.kernel, g, Some(o.report))?, cols)
    }
}

/// The searched or the isotropic kernel, whichever has the larger leave-one-out sum
/// (`(searched, isotropic)`), with the choice in its report; `rows` the isotropic search's.
fn choose_isotropic(
    searched: Fitted,
    isotropic: Fitted,
    (searched_loo, isotropic_loo): (f64, f64),
    rows: usize,
) -> Fitted {
    let kept_isotropic = isotropic_loo > searched_loo;
    let choice = IsotropicChoice {
        searched: searched_loo,
        isotropic: isotropic_loo,
        kept_isotropic,
        isotropic_search_rows: rows,
        compared_rows: None,
    };
    let (component, mut report) = if kept_isotropic { isotropic } else { searched };
    report.isotropic_choice = Some(choice);
    (component, report)
}

impl ExactGp {
    /// Fits the model: inputs `x` (n × d), outputs `y` (n × m), hyperparameters found by maximising
    /// the log marginal likelihood from the default start of `config.kernel`.
    pub fn fit(x: MatRef<'_, f64>, y: MatRef<'_, f64>, config: &GpConfig) -> Result<Self, Error> {
        let start = Kernel::start(config.kernel, x.ncols());
        Self::fit_impl(x, y, Hyperparameters::Optimise(&start), config)
    }

    /// As [`ExactGp::fit`] but the search starts from `start` (its family replaces `config.kernel`).
    pub fn fit_from(x: MatRef<'_, f64>, y: MatRef<'_, f64>, start: &Kernel, config: &GpConfig) -> Result<Self, Error> {
        Self::fit_impl(x, y, Hyperparameters::Optimise(start), config)
    }

    /// Fits with given hyperparameters, no search: one kernel for all outputs, or one per output
    /// ([`OutputMode::Independent`] only). Hyperparameters are for the standardised inputs and
    /// normalised outputs when the config asks for those maps.
    pub fn fit_fixed(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        kernels: &[Kernel],
        config: &GpConfig,
    ) -> Result<Self, Error> {
        let valid = kernels.len() == 1 || (config.outputs == OutputMode::Independent && kernels.len() == y.ncols());
        if !valid {
            return Err(Error::InvalidConfig { field: "kernels", value: kernels.len() as f64 });
        }
        Self::fit_impl(x, y, Hyperparameters::Fixed(kernels), config)
    }

    fn fit_impl(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        how: Hyperparameters<'_>,
        config: &GpConfig,
    ) -> Result<Self, Error> {
        config.validate()?;
        let raw = validate_training_data(x, y)?;
        let m = y.ncols();
        let inputs = if config.standardise_inputs {
            InputStandardiser::fit(&raw)
        } else {
            InputStandardiser::identity(x.ncols())
        };
        let outputs = if config.normalise_outputs { OutputNormaliser::fit(y) } else { OutputNormaliser::identity(m) };
        let xs = inputs.apply_points(&raw);
        let yn = outputs.normalise(y);
        let [groups, followers] = output_groups(&how, config, m)?;
        // A group per pool thread or more: one thread per group, as nested parallelism only adds synchronisation.
        let busy = config.parallelism == Parallelism::Rayon && groups.len() >= rayon::current_num_threads();
        let one_thread = GpConfig { parallelism: Parallelism::Sequential, ..config.clone() };
        let fits = GroupFits { xs: &xs, yn: &yn, config: if busy { &one_thread } else { config }, how: &how };
        let expected = ExpectedGroups::new(if busy { groups.len() } else { 0 });
        let fit_group = |(g, cols): (usize, &Vec<usize>)| {
            let fit = || fits.with_isotropic(fits.fit_searched(g, cols)?, cols);
            if busy { expected.run(fit) } else { fit() }
        };
        let fitted: Vec<_> = match config.parallelism {
            Parallelism::Sequential => groups.iter().enumerate().map(fit_group).collect(),
            Parallelism::Rayon => groups.par_iter().enumerate().map(fit_group).collect(),
        };
        let mut fitted = fitted.into_iter().collect::<Result<Vec<_>, _>>()?;
        // Each follower group from the fitted kernel that explains it best, refined on all rows.
        let leaders: Vec<Kernel> = fitted.iter().map(|(_, r)| r.kernel.clone()).collect();
        let follow = |cols: &Vec<usize>| GroupFits { config, ..fits }.follow(&leaders, cols);
        let followed: Vec<_> = match config.parallelism {
            Parallelism::Sequential => followers.iter().map(follow).collect(),
            Parallelism::Rayon => followers.par_iter().map(follow).collect(),
        };
        fitted.extend(followed.into_iter().collect::<Result<Vec<_>, _>>()?);
        let (components, reports): (Vec<_>, Vec<_>) = fitted.into_iter().unzip();
        Ok(Self {
            inputs,
            outputs,
            x: xs,
            y: yn,
            components,
            parallelism: config.parallelism,
            report: ExactFitReport { components: reports },
        })
    }

    /// What the fit did: hyperparameters, likelihoods, jitter and search per kernel.
    pub fn report(&self) -> &ExactFitReport {
        &self.report
    }

    /// The kernel that models output `output` (for standardised inputs and normalised outputs).
    pub fn kernel_for_output(&self, output: usize) -> Option<&Kernel> {
        self.components.iter().find(|c| c.outputs.contains(&output)).map(|c| &c.kernel)
    }

    /// Total log marginal likelihood of the normalised outputs, summed over kernels.
    pub fn log_marginal_likelihood(&self) -> f64 {
        self.report.components.iter().map(|c| c.log_marginal_likelihood).sum()
    }

    /// Number of training points.
    pub fn training_len(&self) -> usize {
        self.x.len()
    }

    /// Number of inputs `d`.
    pub fn input_dim(&self) -> usize {
        self.x.dim()
    }

    /// Number of outputs `m`.
    pub fn output_count(&self) -> usize {
        self.y.ncols()
    }

    /// The input standardisation applied before the kernel.
    pub fn input_standardiser(&self) -> &InputStandardiser {
        &self.inputs
    }

    /// The output normalisation undone after prediction.
    pub fn output_normaliser(&self) -> &OutputNormaliser {
        &self.outputs
    }
}

/// Rows agree, at least one point, one input and one output, everything finite.
pub fn validate_training_data(x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> Result<Points, Error> {
    if x.nrows() != y.nrows() {
        return Err(Error::RowCountMismatch { input_rows: x.nrows(), output_rows: y.nrows() });
    }
    if x.nrows() == 0 {
        return Err(Error::TooFewPoints { rows: 0, required: 1 });
    }
    if x.ncols() == 0 {
        return Err(Error::NoInputDimensions);
    }
    if y.ncols() == 0 {
        return Err(Error::NoOutputs);
    }
    check_finite_outputs(y)?;
    Points::from_rows(x)
}

/// Every output of `0..m` served by exactly one kernel (`outputs`, per kernel), or prediction
/// would leave it empty.
pub fn check_served<'a>(outputs: impl Iterator<Item = &'a Vec<usize>>, m: usize) -> Result<(), Error> {
    let mut served = vec![0usize; m];
    for &j in outputs.flatten() {
        if j >= m {
            return Err(Error::InputDimensionMismatch { expected: m, found: j + 1 });
        }
        served[j] += 1;
    }
    match served.iter().position(|&k| k != 1) {
        Some(j) => Err(Error::InvalidConfig { field: "report.components.outputs", value: j as f64 }),
        None => Ok(()),
    }
}

impl Component {
    /// `[K⁻¹]ᵢᵢ` for every row: the squared column norms of `L⁻¹`.
    pub(crate) fn inverse_diagonal(&self, par: faer::Par) -> Vec<f64> {
        let inverse = self.factor.inverse_lower(par);
        let n = inverse.nrows();
        // L⁻¹ is lower triangular: column i has entries from row i down.
        (0..n).map(|i| (i..n).map(|k| inverse[(k, i)] * inverse[(k, i)]).sum()).collect()
    }

    /// Per served output, the log predictive probability of Eq. 5.11 summed over rows, for the
    /// normalised outputs the component was built on.
    pub(crate) fn log_predictive(&self, diagonal: &[f64]) -> Vec<f64> {
        let ln_2pi = (2.0 * std::f64::consts::PI).ln();
        (0..self.alpha.ncols())
            .map(|c| {
                diagonal
                    .iter()
                    .enumerate()
                    .map(|(i, &kii)| {
                        let residual = self.alpha[(i, c)] / kii;
                        0.5 * kii.ln() - 0.5 * residual * residual * kii - 0.5 * ln_2pi
                    })
                    .sum()
            })
            .collect()
    }

    /// Factors the kernel matrix (with jitter escalation, or with exactly `fixed_jitter`) and solves
    /// for the weights.
    pub(crate) fn build(
        kernel: Kernel,
        outputs: Vec<usize>,
        x: &Points,
        y: MatRef<'_, f64>,
        fixed_jitter: Option<f64>,
        config: &GpConfig,
        parallelism: Parallelism,
    ) -> Result<(Self, JitterOutcome), Error> {
        let par = parallelism.faer();
        let (evaluator, prepared) = kernel.prepare(x);
        let k = training_covariance(&evaluator, &prepared, kernel.noise_variance(), parallelism);
        let (factor, jitter) = match fixed_jitter {
            None => Factor::with_jitter(&k, &config.jitter, par)?,
            Some(j) => (Factor::with_fixed_jitter(&k, j, par)?, JitterOutcome { added: j, failed_attempts: 0 }),
        };
        let mut alpha = y.to_owned();
        factor.solve_in_place(alpha.as_mut(), par);
        Ok((Self { kernel, outputs, evaluator, prepared, factor, alpha }, jitter))
    }

    /// R&W Eq. 2.30 summed over the served outputs, from the stored factor and weights.
    fn log_marginal_likelihood(&self, y: MatRef<'_, f64>) -> f64 {
        let (n, m) = (y.nrows(), y.ncols());
        let fit: f64 = (0..m).map(|c| (0..n).map(|i| y[(i, c)] * self.alpha[(i, c)]).sum::<f64>()).sum();
        -0.5 * fit
            - 0.5 * m as f64 * self.factor.log_determinant()
            - 0.5 * (n * m) as f64 * (2.0 * std::f64::consts::PI).ln()
    }
}

/// The serialised form: data, maps and report; the factorisation is rebuilt on reading.
#[derive(Serialize, Deserialize)]
struct StoredExactGp {
    inputs: InputStandardiser,
    outputs: OutputNormaliser,
    /// Standardised training inputs, one row per point.
    training_inputs: Vec<Vec<f64>>,
    /// Normalised training outputs, one row per point.
    training_outputs: Vec<Vec<f64>>,
    parallelism: Parallelism,
    report: ExactFitReport,
}

impl From<ExactGp> for StoredExactGp {
    fn from(gp: ExactGp) -> Self {
        let training_inputs = (0..gp.x.len()).map(|i| gp.x.row(i).to_vec()).collect();
        let training_outputs = (0..gp.y.nrows()).map(|i| (0..gp.y.ncols()).map(|j| gp.y[(i, j)]).collect()).collect();
        Self {
            inputs: gp.inputs,
            outputs: gp.outputs,
            training_inputs,
            training_outputs,
            parallelism: gp.parallelism,
            report: gp.report,
        }
    }
}

impl TryFrom<StoredExactGp> for ExactGp {
    type Error = Error;

    fn try_from(s: StoredExactGp) -> Result<Self, Error> {
        let n = s.training_inputs.len();
        let d = s.inputs.mean.len();
        let m = s.outputs.mean.len();
        if s.training_outputs.len() != n {
            return Err(Error::RowCountMismatch { input_rows: n, output_rows: s.training_outputs.len() });
        }
        let x = Mat::from_fn(n, d, |i, j| s.training_inputs[i].get(j).copied().unwrap_or(f64::NAN));
        let y = Mat::from_fn(n, m, |i, j| s.training_outputs[i].get(j).copied().unwrap_or(f64::NAN));
        s.inputs.check(d)?;
        s.outputs.check(m)?;
        let points = validate_training_data(x.as_ref(), y.as_ref())?;
        check_served(s.report.components.iter().map(|c| &c.outputs), m)?;
        let config = GpConfig::default();
        let mut components = Vec::with_capacity(s.report.components.len());
        for c in &s.report.components {
            c.kernel.validate(d)?;
            let yc = Mat::from_fn(n, c.outputs.len(), |i, k| y[(i, c.outputs[k])]);
            let (component, _) = Component::build(
                c.kernel.clone(),
                c.outputs.clone(),
                &points,
                yc.as_ref(),
                Some(c.jitter.added),
                &config,
                s.parallelism,
            )?;
            components.push(component);
        }
        Ok(Self {
            inputs: s.inputs,
            outputs: s.outputs,
            x: points,
            y,
            components,
            parallelism: s.parallelism,
            report: s.report,
        })
    }
}
