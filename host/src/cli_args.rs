//! Value parsers for command-line options with a range: clap reports a rejected value as
//! "invalid value 'V' for '--option <OPTION>': <why>", so every message here names the range.

/// A finite f32 in `[lo, hi]` (NaN and infinities rejected).
pub fn f32_in(lo: f32, hi: f32) -> impl Fn(&str) -> Result<f32, String> + Clone + Send + Sync + 'static {
    move |s: &str| {
        let v: f32 = s.trim().parse().map_err(|_| format!("not a number (expected a value in [{lo}, {hi}])"))?;
        if v.is_finite() && (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{v} is outside the allowed range [{lo}, {hi}]"))
        }
    }
}

/// A finite f32 in `[lo, hi)`.
pub fn f32_in_half_open(lo: f32, hi: f32) -> impl Fn(&str) -> Result<f32, String> + Clone + Send + Sync + 'static {
    let closed = f32_in(lo, hi);
    move |s: &str| match closed(s)? {
        v if v < hi => Ok(v),
        v => Err(format!("{v} is outside the allowed range [{lo}, {hi})")),
    }
}

/// A u32 from the listed values.
pub fn u32_of(allowed: &'static [u32]) -> impl Fn(&str) -> Result<u32, String> + Clone + Send + Sync + 'static {
    move |s: &str| {
        let list = allowed.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
        match s.trim().parse::<u32>() {
            Ok(v) if allowed.contains(&v) => Ok(v),
            _ => Err(format!("allowed values: {list}")),
        }
    }
}

/// An image width or height: 1 to 4096 pixels.
pub fn pixels(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(v) if (1..=4096).contains(&v) => Ok(v),
        _ => Err("allowed range: 1 to 4096 pixels".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let p = f32_in(0.0, 1.0);
        assert_eq!(p("0.5"), Ok(0.5));
        assert_eq!(p("1"), Ok(1.0));
        for bad in ["-1", "nan", "inf", "1.5", "x"] {
            assert!(p(bad).is_err(), "{bad}");
        }
        let h = f32_in_half_open(0.0, 1.0);
        assert!(h("1").is_err() && h("0.99").is_ok());
        let q = u32_of(&[1, 2, 4]);
        assert_eq!(q("2"), Ok(2));
        assert!(q("3").is_err());
    }
}
