//! Measured run times, labelled with how they were measured.

/// Where a time came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingSource {
    /// GPU timestamp queries around the compute pass (kernel time only).
    TimestampQuery,
    /// Host wall clock (includes uploads, submission and readback on the GPU backend).
    WallClock,
}

impl std::fmt::Display for TimingSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TimingSource::TimestampQuery => "timestamp query",
            TimingSource::WallClock => "wall clock",
        })
    }
}

/// A duration and how it was measured.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    pub seconds: f64,
    pub source: TimingSource,
}

impl Timing {
    /// No time (a launch with nothing to do).
    pub fn zero() -> Timing {
        Timing { seconds: 0.0, source: TimingSource::WallClock }
    }

    /// The wall clock since `t0`.
    pub fn since(t0: std::time::Instant) -> Timing {
        Timing { seconds: t0.elapsed().as_secs_f64(), source: TimingSource::WallClock }
    }
}

/// Sum of two timings; wall clock wins if either is wall clock.
impl std::ops::Add for Timing {
    type Output = Timing;
    fn add(self, o: Timing) -> Timing {
        let source = if self.source == o.source { self.source } else { TimingSource::WallClock };
        Timing { seconds: self.seconds + o.seconds, source }
    }
}

/// The 1-minute load average (other processes competing for the cores skew the timings).
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg").ok().and_then(|s| s.split_whitespace().next().map(str::to_string)).unwrap_or_else(|| "?".into())
}

/// The CPU model name, for benchmark reports.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string()))
        .unwrap_or_else(|| "unknown CPU".into())
}

/// (fastest, median) of measured times (seconds; the upper median for an even count). NaN sorts
/// last (`f64::total_cmp`), so a failed measurement never becomes the fastest. Panics on an empty
/// list: every benchmark times at least one run.
pub fn best_and_median(mut v: Vec<f64>) -> (f64, f64) {
    assert!(!v.is_empty(), "no timed runs");
    v.sort_by(|a, b| a.total_cmp(b));
    (v[0], v[v.len() / 2])
}

/// The median of measured times ([`best_and_median`]).
pub fn median(v: Vec<f64>) -> f64 {
    best_and_median(v).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn best_and_median_ignore_nan_and_order() {
        assert_eq!(best_and_median(vec![3.0, 1.0, 2.0]), (1.0, 2.0));
        assert_eq!(best_and_median(vec![f64::NAN, 2.0, 1.0]), (1.0, 2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
    }
}
