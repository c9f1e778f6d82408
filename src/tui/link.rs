//! What the app knows of the link to the terminal, measured from inside: how fast the terminal
//! side drains what we write, and how much is still queued. Pure (the caller passes the time),
//! so the model is testable without a terminal.
//!
//! Writes go to a non-blocking descriptor. While the kernel's queue has room, a write takes
//! everything at once and says nothing about the link; once it is full, a write takes only what
//! the terminal has read meanwhile. So the bytes taken between the first "would block" of a
//! frame and the frame's end, over that time, are the drain rate. From the rate:
//! - the queue is modelled (bytes written, less rate × time), and the writer waits until it is
//!   down to [`LOW_WATER`] of link time (or a little more than a frame's encoding time) before
//!   it takes the next frame, so a frame reaches the screen soon after it is encoded rather than
//!   behind a full queue;
//! - each frame gets a byte budget of [`FRAME_TIME`] of link time.
//!
//! An unmeasured link (writes never blocked) counts as fast: no budget, exact frames. A rate
//! that has not been re-measured for a while creeps up ([`PROBE_GROWTH`] per frame that went
//! out without blocking), so a link that got faster is found again.

use std::time::{Duration, Instant};

/// Link time one frame may take: about fifteen frames a second. Longer frames get a fast
/// link to exact sooner after a key is released; shorter ones show each step of a held key
/// sooner on a slow one (65 ms was the best of 50, 65 and 80 in `examples/slow_link.rs`).
pub const FRAME_TIME: Duration = Duration::from_millis(65);
/// The writer takes the next frame once the queue is down to this much link time: enough to
/// keep the link busy while the next frame is encoded, little enough that it shows soon.
pub const LOW_WATER: Duration = Duration::from_millis(25);
/// The queue is kept at least this many times the last frame's encoding time (see
/// [`Link::wait`]).
const ENCODE_MARGIN: f64 = 1.5;
/// A drain-rate sample needs at least this much time with the queue full (shorter ones are
/// dominated by scheduling noise and by the burst a link lets through after a pause).
const MIN_SAMPLE: Duration = Duration::from_millis(30);
/// Weight of a new rate sample against the estimate when it is lower: an overestimate fills
/// the queue and delays every frame, so the estimate falls fast...
const WEIGHT_DOWN: f64 = 0.5;
/// ... and rises slowly (a short sample overestimates by the link's burst).
const WEIGHT_UP: f64 = 0.25;
/// The estimate grows by this factor for each frame that went out without blocking, back up
/// to the rate a long sample measured ([`LONG_SAMPLE`]): an underestimate leaves the link
/// idle...
const RECOVER_GROWTH: f64 = 1.05;
/// ... and past it by this factor (about 8 % a second at fifteen frames a second), so a link
/// that got faster is found while an overestimate (which fills the queue and delays every
/// frame) stays rare.
const PROBE_GROWTH: f64 = 1.005;
/// A sample over this long is not inflated by the burst a link lets through after a pause: the
/// estimate recovers quickly up to the largest such sample.
const LONG_SAMPLE: Duration = Duration::from_millis(100);
/// The smallest frame budget: a status line and a few cells always fit.
const MIN_BUDGET: usize = 512;

/// The link model.
#[derive(Clone, Copy, Debug)]
pub struct Link {
    /// Drain rate in bytes per second, once measured.
    rate: Option<f64>,
    /// Bytes queued at `at`, as modelled.
    queued: f64,
    at: Instant,
    /// The queue when a write last blocked: the kernel's (and terminal's) buffer.
    capacity: f64,
    /// The largest sample taken over at least [`LONG_SAMPLE`].
    ceiling: f64,
}

impl Link {
    /// A link not measured yet.
    pub fn new(now: Instant) -> Link {
        Link {
            rate: None,
            queued: 0.0,
            at: now,
            capacity: 0.0,
            ceiling: 0.0,
        }
    }

    /// The measured drain rate in bytes per second, if any.
    pub fn rate(&self) -> Option<f64> {
        self.rate
    }

    /// Bytes believed still queued at `now` (0 on an unmeasured link).
    pub fn queued(&self, now: Instant) -> f64 {
        match self.rate {
            Some(r) => {
                (self.queued - r * now.saturating_duration_since(self.at).as_secs_f64()).max(0.0)
            }
            None => self.queued,
        }
    }

    /// `n` bytes were written at `now`.
    pub fn wrote(&mut self, n: usize, now: Instant) {
        self.queued = self.queued(now) + n as f64;
        self.at = now;
    }

    /// A write would have blocked at `now` for the first time in a frame: the queue is full,
    /// and the model's queue is the best guess of how much it holds.
    pub fn full(&mut self, now: Instant) {
        self.capacity = self.queued(now);
        self.at = now;
    }

    /// A frame is written: `drained` bytes were taken over `full_for` with the queue full (none
    /// if it never blocked).
    pub fn frame_done(&mut self, drained: usize, full_for: Option<Duration>, now: Instant) {
        match full_for {
            Some(t) if t >= MIN_SAMPLE && drained > 0 => {
                self.sample(drained, t);
                self.queued = self.capacity;
                self.at = now;
            }
            Some(_) => {
                self.queued = self.capacity;
                self.at = now;
            }
            None => {
                if let Some(r) = self.rate.as_mut() {
                    *r = if *r < self.ceiling {
                        (*r * RECOVER_GROWTH).min(self.ceiling)
                    } else {
                        *r * PROBE_GROWTH
                    };
                }
                if self.rate.is_none() {
                    // Nothing can be known of an unmeasured queue: start afresh next frame.
                    self.queued = 0.0;
                }
            }
        }
    }

    /// `bytes` went through the link in `t`: a rate sample, taken if `t` is long enough.
    fn sample(&mut self, bytes: usize, t: Duration) {
        if t < MIN_SAMPLE || bytes == 0 {
            return;
        }
        let sample = bytes as f64 / t.as_secs_f64();
        if t >= LONG_SAMPLE {
            self.ceiling = self.ceiling.max(sample);
        }
        self.rate = Some(match self.rate {
            Some(r) if sample < r => r + WEIGHT_DOWN * (sample - r),
            Some(r) => r + WEIGHT_UP * (sample - r),
            None => sample,
        });
    }

    /// The terminal acknowledged at `now` everything written before a query: `rate` is the
    /// end-to-end rate the answers measure (if any yet), and `unacknowledged` bytes written
    /// since are all that can still be queued.
    pub fn acknowledged(&mut self, rate: Option<f64>, unacknowledged: usize, now: Instant) {
        if rate.is_some() {
            self.rate = rate;
        }
        self.queued = unacknowledged as f64;
        self.at = now;
    }

    /// How long after `now` the queue is down to [`LOW_WATER`] of link time, or to the time
    /// the next frame takes to encode (`encode`, measured on the last one) with
    /// [`ENCODE_MARGIN`] if that is longer: so the link does not run dry while the next frame
    /// is encoded, even on a loaded machine.
    pub fn wait(&self, now: Instant, encode: Duration) -> Duration {
        match self.rate {
            Some(r) => {
                let low = LOW_WATER.max(encode.mul_f64(ENCODE_MARGIN));
                let excess = self.queued(now) - r * low.as_secs_f64();
                Duration::from_secs_f64((excess / r).max(0.0))
            }
            None => Duration::ZERO,
        }
    }

    /// Bytes the next frame may take, or `None` for no limit (an unmeasured, fast link).
    pub fn budget(&self) -> Option<usize> {
        self.rate
            .map(|r| ((r * FRAME_TIME.as_secs_f64()) as usize).max(MIN_BUDGET))
    }
}

/// How long the first query may go unanswered before the terminal counts as one that does not
/// answer: then no more queries, and the link is measured by the drain rate alone.
pub const ACK_PROBE_TIMEOUT: Duration = Duration::from_secs(1);
/// Once the terminal answers, how long the writer waits for the previous frame's
/// acknowledgement before it gives up on them (and falls back to the drain rate). Longer than
/// a whole unbudgeted first frame takes over a slow link.
pub const ACK_WAIT: Duration = Duration::from_secs(2);

/// The answers' rate is the least of the last this many frames' rates: a link with a token
/// bucket (pv, a shaped uplink) or a terminal that reads in bursts lets some frames through at
/// once after an idle spell, and an overestimate fills the buffers behind the pty, whereas an
/// underestimate only makes a frame approximate for a little longer.
const ACK_WINDOW: usize = 6;

/// Whether the terminal acknowledges frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AckState {
    /// No query sent yet.
    Unasked,
    /// The first query went out at this time; no reply yet.
    Probing(Instant),
    /// The terminal answers: every frame ends with a query.
    On,
    /// It did not answer (or stopped): no more queries.
    Off,
}

/// Pacing by the terminal's acknowledgement, for links whose buffers the drain rate cannot see
/// (over SSH, the pty drains into sshd's and TCP's buffers at once, however slow the network).
/// The writer ends each frame with a query the terminal answers only once it has processed
/// everything before it ([`ACK_QUERY`](super::input::ACK_QUERY)); the time from writing to the
/// answer gives the end-to-end latency (the least such time: the first query goes out alone)
/// and throughput (the bytes since the previous query, over the time from when they could
/// first arrive to the answer), fed into [`Link`]. The writer keeps at most one acknowledged
/// frame outstanding while the app encodes the next ([`Acks::waiting`]). Pure, like [`Link`].
#[derive(Clone, Debug)]
pub struct Acks {
    state: AckState,
    /// Queries in flight, oldest first: when the bytes before each began to be written, and how
    /// many there were since the query before.
    sent: std::collections::VecDeque<(Instant, usize)>,
    /// Bytes written since the last query, and when the first of them was.
    unqueried: Option<(Instant, usize)>,
    /// When the last acknowledgement arrived.
    last: Option<Instant>,
    /// The latest per-frame rates (bytes per second), newest last, at most [`ACK_WINDOW`].
    recent: std::collections::VecDeque<f64>,
    /// The least time from a write to its acknowledgement: the link's latency.
    latency: Option<Duration>,
}

impl Acks {
    /// Nothing asked yet.
    pub fn new() -> Acks {
        Acks {
            state: AckState::Unasked,
            sent: Default::default(),
            unqueried: None,
            last: None,
            recent: Default::default(),
            latency: None,
        }
    }

    /// What to write around a frame that begins at `now`: (a query before it, a query after
    /// it). The very first frame has both (the answer to the first measures latency alone, the
    /// second the frame's throughput, so the link is known before the first key); once the
    /// terminal has answered, every frame is followed by one; while the first is unanswered,
    /// and after [`ACK_PROBE_TIMEOUT`] without an answer, none.
    pub fn queries(&mut self, now: Instant) -> (bool, bool) {
        self.expire(now);
        match self.state {
            AckState::Unasked => {
                self.state = AckState::Probing(now);
                (true, true)
            }
            AckState::On => (false, true),
            AckState::Probing(_) | AckState::Off => (false, false),
        }
    }

    /// A frame of `bytes` (queries included) was written, beginning at `start`; `before` and
    /// `after` say where its queries were (as [`Acks::queries`] said).
    pub fn wrote(&mut self, start: Instant, bytes: usize, before: bool, after: bool) {
        if before {
            self.query(start);
        }
        let (at, n) = self.unqueried.unwrap_or((start, 0));
        self.unqueried = Some((at, n + bytes));
        if after {
            self.query(start);
        }
    }

    fn query(&mut self, now: Instant) {
        let (at, n) = self.unqueried.take().unwrap_or((now, 0));
        self.sent.push_back((at, n));
    }

    /// An acknowledgement arrived at `now`: the state and `link` learn from it.
    pub fn acked(&mut self, now: Instant, link: &mut Link) {
        let Some((at, bytes)) = self.sent.pop_front() else {
            return; // a reply to a query given up on
        };
        if matches!(self.state, AckState::Probing(_)) {
            self.state = AckState::On;
            // Frames written while unanswered had no query: when their bytes went is unknown.
            self.unqueried = None;
        }
        if self.state != AckState::On {
            return;
        }
        let took = now.saturating_duration_since(at);
        let latency = self.latency.map_or(took, |l| l.min(took));
        self.latency = Some(latency);
        // The bytes could not arrive before the link's latency, nor be taken before the
        // previous acknowledgement (the link was busy with what came before).
        let mut begin = at + latency;
        if let Some(last) = self.last {
            begin = begin.max(last);
        }
        self.last = Some(now);
        let unacknowledged =
            self.sent.iter().map(|s| s.1).sum::<usize>() + self.unqueried.map_or(0, |u| u.1);
        let t = now.saturating_duration_since(begin);
        if t >= MIN_SAMPLE && bytes > 0 {
            if self.recent.len() == ACK_WINDOW {
                self.recent.pop_front();
            }
            self.recent.push_back(bytes as f64 / t.as_secs_f64());
        }
        let rate = self.recent.iter().copied().reduce(f64::min);
        link.acknowledged(rate, unacknowledged, now);
    }

    /// Whether the writer should wait for an acknowledgement before taking the next frame:
    /// the terminal answers and more than one frame is unacknowledged.
    pub fn waiting(&self) -> bool {
        self.state == AckState::On && self.sent.len() > 1
    }

    /// No acknowledgement came within [`ACK_WAIT`]: the terminal stopped answering; stop
    /// asking and fall back to the drain rate.
    pub fn give_up(&mut self) {
        self.state = AckState::Off;
        self.sent.clear();
    }

    /// Whether the terminal answers (the status line's estimate is then end to end).
    pub fn on(&self) -> bool {
        self.state == AckState::On
    }

    /// The link's latency as measured by the acknowledgements, once answered.
    #[cfg(test)]
    pub fn latency(&self) -> Option<Duration> {
        self.latency
    }

    /// Whether answers are due: queries are unanswered and the terminal answers, or may.
    pub fn outstanding(&self) -> bool {
        !self.sent.is_empty() && matches!(self.state, AckState::On | AckState::Probing(_))
    }

    /// Stops asking if the first query has gone unanswered for [`ACK_PROBE_TIMEOUT`] at `now`.
    pub fn expire(&mut self, now: Instant) {
        if let AckState::Probing(t) = self.state
            && now.saturating_duration_since(t) >= ACK_PROBE_TIMEOUT
        {
            self.give_up();
        }
    }
}

impl Default for Acks {
    fn default() -> Acks {
        Acks::new()
    }
}

/// The rate as the status line shows it: `1.0Mbit/s`, `250kbit/s`; `fast` when unmeasured.
pub fn describe(rate: Option<f64>) -> String {
    match rate {
        None => "fast".into(),
        Some(r) => {
            let bits = r * 8.0;
            if bits >= 1e6 {
                format!("{:.1}Mbit/s", bits / 1e6)
            } else {
                format!("{:.0}kbit/s", bits / 1e3)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    #[test]
    fn an_unmeasured_link_is_fast_and_unlimited() {
        let t = Instant::now();
        let mut l = Link::new(t);
        l.wrote(100_000, t);
        l.frame_done(0, None, t + MS);
        assert_eq!(
            (l.budget(), l.wait(t + MS, MS), describe(l.rate())),
            (None, Duration::ZERO, "fast".into())
        );
    }

    #[test]
    fn a_blocked_frame_measures_the_rate_and_the_writer_waits_for_the_queue() {
        let t = Instant::now();
        let mut l = Link::new(t);
        // 20 kB go in at once, then the queue is full; 125 kB drain over the next second.
        l.wrote(20_000, t);
        l.full(t);
        l.wrote(125_000, t + 1000 * MS);
        l.frame_done(125_000, Some(1000 * MS), t + 1000 * MS);
        assert_eq!(l.rate(), Some(125_000.0));
        assert_eq!(describe(l.rate()), "1.0Mbit/s");
        assert_eq!(l.budget(), Some(8125));
        // The queue is full (20 kB = 160 ms of link): the writer waits it down to 25 ms.
        let wait = l.wait(t + 1000 * MS, MS);
        assert!((wait.as_secs_f64() - 0.135).abs() < 1e-3, "{wait:?}");
        assert_eq!(l.wait(t + 1200 * MS, MS), Duration::ZERO);
        // A frame that took 40 ms to encode: the writer comes back at 60 ms of queue.
        let slow = l.wait(t + 1000 * MS, 40 * MS);
        assert!((slow.as_secs_f64() - 0.100).abs() < 1e-3, "{slow:?}");
        assert_eq!(l.queued(t + 1200 * MS), 0.0);
    }

    #[test]
    fn slow_acknowledgements_shrink_the_budget_and_keep_one_frame_in_flight() {
        let t = Instant::now();
        let mut l = Link::new(t);
        let mut a = Acks::new();
        // The first frame is preceded and followed by a query; the first reply comes after
        // 10 ms of latency.
        assert_eq!(a.queries(t), (true, true));
        a.wrote(t, 20_006, true, true);
        assert!(!a.waiting(), "no waiting before the terminal has answered");
        a.acked(t + 10 * MS, &mut l);
        assert!(a.on());
        assert_eq!(a.latency(), Some(10 * MS));
        assert_eq!(l.rate(), None, "latency alone is no rate");
        // Writes never block (sshd takes everything), so the drain rate sees nothing (the
        // writer leaves `frame_done` out while acknowledged). Each 20 kB frame is answered
        // 200 ms after the one before: 100 kB/s.
        let mut now = t + 10 * MS;
        for _ in 0..5 {
            assert_eq!(a.queries(now), (false, true));
            a.wrote(now, 20_000, false, true);
            l.wrote(20_000, now);
            assert!(a.waiting(), "two frames in flight: wait for the older");
            now += 200 * MS;
            a.acked(now, &mut l);
            assert!(!a.waiting());
        }
        let rate = l.rate().expect("measured by acknowledgements");
        assert!((rate - 100_000.0).abs() < 1_000.0, "{rate}");
        assert_eq!(describe(l.rate()), "800kbit/s");
        assert_eq!(l.budget(), Some(6_500));
        // The queue model knows a frame is still in flight.
        assert_eq!(l.queued(now), 20_000.0);
        // A burst (20 kB answered 40 ms after the one before: 500 kB/s) does not raise it.
        a.queries(now);
        a.wrote(now, 20_000, false, true);
        a.acked(now + 200 * MS, &mut l);
        a.acked(now + 240 * MS, &mut l);
        assert_eq!(l.rate(), Some(rate));
    }

    #[test]
    fn a_terminal_that_never_answers_is_asked_once_and_changes_nothing() {
        let t = Instant::now();
        let mut l = Link::new(t);
        let mut a = Acks::new();
        assert_eq!(a.queries(t), (true, true));
        a.wrote(t, 50_006, true, true);
        // Within the first second, frames go out without queries or waiting.
        for ms in [100, 500, 999] {
            assert_eq!(a.queries(t + ms * MS), (false, false));
            a.wrote(t + ms * MS, 50_000, false, false);
            assert!(!a.waiting());
        }
        // After it, never again; a late reply changes nothing.
        assert_eq!(a.queries(t + 1000 * MS), (false, false));
        a.acked(t + 1500 * MS, &mut l);
        assert_eq!(a.queries(t + 2000 * MS), (false, false));
        assert!(!a.on() && !a.waiting() && !a.outstanding());
        assert_eq!((l.rate(), l.budget()), (None, None));
    }

    #[test]
    fn frames_that_never_block_let_the_estimate_grow() {
        let t = Instant::now();
        let mut l = Link::new(t);
        l.full(t);
        l.frame_done(10_000, Some(100 * MS), t);
        let before = l.budget().unwrap();
        for _ in 0..200 {
            l.frame_done(0, None, t);
        }
        assert!(l.budget().unwrap() > 2 * before);
        assert_eq!(describe(Some(30_000.0)), "240kbit/s");
    }
}
