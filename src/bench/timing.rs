//! The one timing harness: a warm-up run, then timed runs, summarised by their median. Every
//! time comes from the frame's own clock (`FrameStats::elapsed`), so what is timed is the
//! render and nothing around it.

use std::time::Duration;

/// How many runs to time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Runs {
    /// Timed runs at least (after one warm-up run).
    pub min: u32,
    /// Keep running while the timed runs add up to less than this (a frame of a few
    /// milliseconds is at the mercy of the scheduler; more runs steady its median cheaply)...
    pub min_total: Duration,
    /// ...but never more than this many timed runs.
    pub max: u32,
}

/// The times of one measurement, sorted.
#[derive(Clone, Debug, PartialEq)]
pub struct Timing {
    /// Every timed run, fastest first (never empty).
    pub sorted: Vec<Duration>,
}

impl Timing {
    /// The median (the mean of the middle two for an even count).
    pub fn median(&self) -> Duration {
        let (s, n) = (&self.sorted, self.sorted.len());
        if n % 2 == 1 {
            s[n / 2]
        } else {
            (s[n / 2 - 1] + s[n / 2]) / 2
        }
    }

    /// The fastest run.
    pub fn min(&self) -> Duration {
        self.sorted[0]
    }

    /// The slowest run.
    pub fn max(&self) -> Duration {
        self.sorted[self.sorted.len() - 1]
    }

    /// How many runs were timed.
    pub fn runs(&self) -> u32 {
        self.sorted.len() as u32
    }
}

/// Runs `once` one untimed time (the warm-up), then as `runs` says; `once` returns the time of
/// its run. `tick` is called after the warm-up and after each of the first `runs.min` runs
/// (progress counts those).
pub fn measure(runs: Runs, mut once: impl FnMut() -> Duration, mut tick: impl FnMut()) -> Timing {
    once();
    tick();
    let min = runs.min.max(1) as usize;
    let max = runs.max.max(runs.min).max(1) as usize;
    let mut sorted = Vec::with_capacity(min);
    let mut total = Duration::ZERO;
    while sorted.len() < min || (total < runs.min_total && sorted.len() < max) {
        let t = once();
        sorted.push(t);
        total += t;
        if sorted.len() <= min {
            tick();
        }
    }
    sorted.sort_unstable();
    Timing { sorted }
}

/// Milliseconds, as the tables print them.
pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(ms: &[u64]) -> Timing {
        let mut sorted: Vec<Duration> = ms.iter().map(|&m| Duration::from_millis(m)).collect();
        sorted.sort_unstable();
        Timing { sorted }
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(timing(&[9, 1, 2]).median(), Duration::from_millis(2));
        assert_eq!(timing(&[1, 3, 4, 9]).median(), Duration::from_micros(3500));
        assert_eq!(timing(&[4, 1, 3]).min(), Duration::from_millis(1));
        assert_eq!(timing(&[4, 1, 3]).max(), Duration::from_millis(4));
    }

    #[test]
    fn warm_up_is_untimed_and_fast_runs_repeat_up_to_the_cap() {
        // Each run "takes" 1 ms: the warm-up (5 ms) is not among the times.
        let mut calls = 0;
        let mut ticks = 0;
        let runs = Runs {
            min: 3,
            min_total: Duration::from_millis(10),
            max: 7,
        };
        let t = measure(
            runs,
            || {
                calls += 1;
                Duration::from_millis(if calls == 1 { 5 } else { 1 })
            },
            || ticks += 1,
        );
        assert_eq!(t.runs(), 7, "ran until the cap, short of 10 ms");
        assert_eq!(calls, 8, "one warm-up + 7 timed");
        assert_eq!(ticks, 4, "the warm-up and the first 3 runs");
        assert_eq!(t.max(), Duration::from_millis(1));
        let slow = measure(runs, || Duration::from_millis(20), || {});
        assert_eq!(slow.runs(), 3, "enough time after the minimum runs");
    }
}
