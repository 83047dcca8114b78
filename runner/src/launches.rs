//! The one chunked-launch loop: a long piece of work (samples of a render, sample chunks of a
//! table) as consecutive launches in item order, so sums kept in launch order are the same bits
//! whatever the launch size, with progress and a stop between launches.

use crate::timing::Timing;
use anyhow::{bail, Result};

/// Items `0..total` in consecutive launches of at most `per_launch` items, in item order:
/// `launch(first, count)` runs one and returns its time. Between launches, once at least one has
/// run, `stop()` may end the loop early. `total` = 0 makes one launch of 0 items (for a launch
/// that does other work besides its items). Returns the items done and the summed launch time.
///
/// ```
/// let mut seen = Vec::new();
/// let t = runner::Timing { seconds: 1.0, source: runner::TimingSource::WallClock };
/// let (done, time) = runner::in_launches(10, 4, || false, |first, n| { seen.push((first, n)); Ok(t) })?;
/// assert_eq!((done, seen), (10, vec![(0, 4), (4, 4), (8, 2)]));
/// assert_eq!(time.seconds, 3.0);
/// # Ok::<(), anyhow::Error>(())
/// ```
pub fn in_launches(total: u32, per_launch: u32, stop: impl Fn() -> bool, mut launch: impl FnMut(u32, u32) -> Result<Timing>) -> Result<(u32, Timing)> {
    if per_launch == 0 {
        bail!("at least one item per launch");
    }
    let mut done = 0;
    let mut time: Option<Timing> = None;
    while time.is_none() || (done < total && !stop()) {
        let n = (total - done).min(per_launch);
        let t = launch(done, n)?;
        time = Some(match time {
            Some(a) => a + t,
            None => t,
        });
        done += n;
    }
    Ok((done, time.expect("at least one launch")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TimingSource;

    #[test]
    fn launches_cover_the_items_in_order_and_stop_between_launches() {
        let t = Timing { seconds: 0.5, source: TimingSource::WallClock };
        let mut seen = Vec::new();
        let (done, _) = in_launches(0, 3, || false, |f, n| {
            seen.push((f, n));
            Ok(t)
        }).unwrap();
        assert_eq!((done, &seen), (0, &vec![(0, 0)]), "one launch when there is nothing to do");
        seen.clear();
        let (done, _) = in_launches(7, 7, || true, |f, n| {
            seen.push((f, n));
            Ok(t)
        }).unwrap();
        assert_eq!((done, &seen), (7, &vec![(0, 7)]), "a stop before the first launch is not honoured");
        seen.clear();
        let calls = std::cell::Cell::new(0);
        let (done, time) = in_launches(9, 2, || calls.get() == 2, |f, n| {
            calls.set(calls.get() + 1);
            seen.push((f, n));
            Ok(t)
        })
        .unwrap();
        assert_eq!((done, &seen, time.seconds), (4, &vec![(0, 2), (2, 2)], 1.0), "stopped after two launches");
        assert!(in_launches(1, 0, || false, |_, _| Ok(t)).is_err());
        let e = in_launches(5, 2, || false, |f, _| if f == 2 { anyhow::bail!("launch failed") } else { Ok(t) }).unwrap_err();
        assert_eq!(e.to_string(), "launch failed");
    }
}
