//! Value parsers for command-line options with a range: clap reports a rejected value as
//! "invalid value 'V' for '--option <OPTION>': <why>", so every message here names the range.

/// A finite f32 in `[lo, hi]` (NaN and infinities rejected).
pub fn f32_in(lo: f32, hi: f32) -> impl Fn(&str) -> Result<f32, String> + Clone + Send + Sync + 'static {
    move |s: &str| finite_f32(s, |v| (lo..=hi).contains(&v), &format!("[{lo}, {hi}]"))
}

/// A finite f32 in `[lo, hi)`.
pub fn f32_in_half_open(lo: f32, hi: f32) -> impl Fn(&str) -> Result<f32, String> + Clone + Send + Sync + 'static {
    move |s: &str| finite_f32(s, |v| lo <= v && v < hi, &format!("[{lo}, {hi})"))
}

/// Parse a finite f32 that `ok` accepts; errors name `range`.
fn finite_f32(s: &str, ok: impl Fn(f32) -> bool, range: &str) -> Result<f32, String> {
    let v: f32 = s.trim().parse().map_err(|_| format!("not a number (expected a value in {range})"))?;
    if v.is_finite() && ok(v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside the allowed range {range}"))
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

/// One of the named values `all` of a library enum (whose crate has no clap), by the name
/// `name` gives it; `--help` lists the names.
pub fn named<T: Copy + Send + Sync + 'static>(all: &'static [T], name: fn(T) -> &'static str) -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(all.iter().map(|v| name(*v))).map(move |s| *all.iter().find(|v| name(**v) == s).expect("a listed name"))
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
