//! Where the time of a long computation goes: wall and CPU seconds per named phase.
//!
//! A computation marks its phases with [`phase`]; nothing is recorded unless a caller asked for it
//! with [`record`], so library code can mark phases at no cost to callers who do not care. Phases
//! nest: a phase started inside another is recorded under the outer's name (`"gp / search"`), and
//! the outer's time includes it. A phase run several times (a fold's fit, once per fold) is one
//! entry with its `calls` and the summed time, at the place of its first call.
//!
//! The recorder belongs to the thread that called [`record`]: phases marked on other threads (the
//! work a rayon pool does inside a phase) are not entries of their own but are in the CPU time of
//! the phase that started them, since CPU time is the whole process's.
//!
//! ```
//! let (sum, timings) = timings::record(|| {
//!     timings::phase("read", || std::hint::black_box(2 + 2));
//!     timings::phase("fit", || timings::phase("search", || (0..1000u64).sum::<u64>()))
//! });
//! assert_eq!(sum, 499_500);
//! let names: Vec<&str> = timings.phases.iter().map(|p| p.phase.as_str()).collect();
//! assert_eq!(names, ["read", "fit", "fit / search"]);
//! ```

#![deny(missing_docs)]

use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::time::{Duration, Instant};

/// The time of one phase, summed over its calls.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseTime {
    /// The phase's name, after the names of the phases it ran in (`"outer / inner"`).
    pub phase: String,
    /// How many times it ran.
    pub calls: usize,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds of the whole process (every thread) while it ran: above `wall_s` where the work
    /// ran in parallel.
    pub cpu_s: f64,
}

/// The phases of a computation, in the order each first started.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// One entry per distinct phase name.
    pub phases: Vec<PhaseTime>,
}

impl Timings {
    /// The phase named `phase` (the whole nested name), if it ran.
    pub fn get(&self, phase: &str) -> Option<&PhaseTime> {
        self.phases.iter().find(|p| p.phase == phase)
    }

    /// The phases that took at least `seconds` of wall time, in order.
    pub fn above(&self, seconds: f64) -> impl Iterator<Item = &PhaseTime> {
        self.phases.iter().filter(move |p| p.wall_s >= seconds)
    }

    fn add(&mut self, phase: String, wall: Duration, cpu: Duration, at: usize) {
        match self.phases.iter_mut().find(|p| p.phase == phase) {
            Some(p) => {
                p.calls += 1;
                p.wall_s += wall.as_secs_f64();
                p.cpu_s += cpu.as_secs_f64();
            }
            None => self.phases.insert(
                at.min(self.phases.len()),
                PhaseTime { phase, calls: 1, wall_s: wall.as_secs_f64(), cpu_s: cpu.as_secs_f64() },
            ),
        }
    }
}

/// What a started phase is told: its whole name, for a progress display.
pub type OnStart = Box<dyn Fn(&str)>;

struct Recorder {
    timings: Timings,
    /// The names of the phases running now, outermost first.
    open: Vec<String>,
    on_start: Option<OnStart>,
}

thread_local! {
    static RECORDER: RefCell<Option<Recorder>> = const { RefCell::new(None) };
}

fn process_cpu() -> Duration {
    // A process whose CPU clock cannot be read reports no CPU time rather than failing the work.
    cpu_time::ProcessTime::try_now().map_or(Duration::ZERO, |t| t.as_duration())
}

/// Runs `work` as the phase `name`: recorded when a [`record`] on this thread is running, run
/// as it is otherwise.
pub fn phase<T>(name: &str, work: impl FnOnce() -> T) -> T {
    let started = RECORDER.with_borrow_mut(|recorder| {
        let recorder = recorder.as_mut()?;
        let full = match recorder.open.last() {
            Some(outer) => format!("{outer} / {name}"),
            None => name.to_owned(),
        };
        if let Some(on_start) = &recorder.on_start {
            on_start(&full);
        }
        recorder.open.push(full);
        // The entry goes where the phase started, before the phases it will contain.
        Some((recorder.timings.phases.len(), Instant::now(), process_cpu()))
    });
    let result = work();
    if let Some((at, wall, cpu)) = started {
        let (wall, cpu) = (wall.elapsed(), process_cpu().saturating_sub(cpu));
        RECORDER.with_borrow_mut(|recorder| {
            if let Some(recorder) = recorder.as_mut()
                && let Some(full) = recorder.open.pop()
            {
                recorder.timings.add(full, wall, cpu, at);
                if let Some(outer) = recorder.open.last().cloned()
                    && let Some(on_start) = &recorder.on_start
                {
                    on_start(&outer);
                }
            }
        });
    }
    result
}

/// Runs `work` recording the phases it marks on this thread, and returns them. Inside another
/// `record` it records its own phases apart and the outer one sees none of them.
pub fn record<T>(work: impl FnOnce() -> T) -> (T, Timings) {
    record_with(None, work)
}

/// [`record`], telling `on_start` the whole name of each phase as it starts (and the outer
/// phase's name again when an inner one ends): a progress display's feed.
pub fn record_with<T>(on_start: Option<OnStart>, work: impl FnOnce() -> T) -> (T, Timings) {
    let fresh = Recorder { timings: Timings::default(), open: Vec::new(), on_start };
    let outer = RECORDER.with_borrow_mut(|recorder| recorder.replace(fresh));
    let result = work();
    let mine = RECORDER.with_borrow_mut(|recorder| std::mem::replace(recorder, outer));
    (result, mine.map(|r| r.timings).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};

    #[test]
    fn phases_outside_a_recording_run_and_leave_nothing() {
        assert_eq!(phase("alone", || 7), 7);
        let (_, timings) = record(|| ());
        assert!(timings.phases.is_empty());
    }

    #[test]
    fn a_repeated_phase_is_one_entry_with_its_calls_summed_at_its_first_place() {
        let ((), timings) = record(|| {
            phase("first", || ());
            for _ in 0..3 {
                phase("fold", || phase("fit", || std::thread::sleep(Duration::from_millis(2))));
            }
            phase("last", || ());
        });
        let names: Vec<(&str, usize)> = timings.phases.iter().map(|p| (p.phase.as_str(), p.calls)).collect();
        assert_eq!(names, [("first", 1), ("fold", 3), ("fold / fit", 3), ("last", 1)]);
        let fold = timings.get("fold").unwrap();
        assert!(fold.wall_s >= 0.006 && fold.wall_s >= timings.get("fold / fit").unwrap().wall_s);
        assert_eq!(timings.above(0.005).count(), 2);
    }

    #[test]
    fn cpu_time_counts_the_work_of_the_phase() {
        let ((), timings) = record(|| {
            phase("spin", || {
                // Until this thread has had 60 ms of CPU, however long a loaded machine makes
                // that take: a bound on the wall time failed in CI under load 15 (4 ms of CPU in
                // 60 ms of wall).
                let started = cpu_time::ThreadTime::now();
                let mut x = 0u64;
                while started.elapsed() < Duration::from_millis(60) {
                    x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                }
            })
        });
        let spin = timings.get("spin").unwrap();
        // The process's CPU time holds this thread's (the margin is for the clocks' rounding).
        assert!(spin.cpu_s >= 0.055, "{spin:?}");
    }

    #[test]
    fn a_nested_recording_keeps_its_phases_apart_and_the_progress_feed_hears_each_start() {
        let heard = Arc::new(Mutex::new(Vec::new()));
        let feed = Arc::clone(&heard);
        let (inner, outer) =
            record_with(Some(Box::new(move |name| feed.lock().unwrap().push(name.to_owned()))), || {
                phase("a", || {
                    phase("b", || ());
                    record(|| phase("hidden", || ())).1
                })
            });
        assert_eq!(inner.phases.len(), 1);
        let names: Vec<&str> = outer.phases.iter().map(|p| p.phase.as_str()).collect();
        assert_eq!(names, ["a", "a / b"]);
        assert_eq!(*heard.lock().unwrap(), ["a", "a / b", "a"]);
    }

    #[test]
    fn timings_serialise_as_the_fit_report_prints_them() {
        let timings = Timings { phases: vec![PhaseTime { phase: "gp".into(), calls: 2, wall_s: 1.5, cpu_s: 2.75 }] };
        let json = serde_json::to_string(&timings).unwrap();
        assert_eq!(json, r#"{"phases":[{"phase":"gp","calls":2,"wall_s":1.5,"cpu_s":2.75}]}"#);
    }
}
