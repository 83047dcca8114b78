//! `host ssr` as a user runs it (64x64, CPU backend): skipping the reference, the printed frame
//! and reference times, the lit frame, one convention for pixels without a reflection, and the
//! debug images' legends and fixed scales.

use host::io::{colormap, read_exr};
use host::ssr::legend::{self, strip_height, NO_VALUE};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const N: usize = 64;

fn host(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).env("XDG_RUNTIME_DIR", std::env::temp_dir()).output().expect("running host")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Run `host ssr` at 64x64 on the CPU with `extra` options; returns the output EXR path and the
/// command's text.
fn ssr(dir: &Path, extra: &[&str]) -> (PathBuf, String) {
    let out = dir.join("s.exr");
    let n = N.to_string();
    let mut args = vec!["ssr", "--scene", "floor", "--width", &n, "--height", &n, "--device", "cpu", "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = host(&args);
    assert!(o.status.success(), "{}", text(&o));
    (out, text(&o))
}

fn beside(out: &Path, suffix: &str) -> PathBuf {
    PathBuf::from(format!("{}.{suffix}", out.with_extension("").display()))
}

fn png(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
}

/// The colours that occur in the legend strip below a debug image.
fn strip_colours(img: &image::RgbImage) -> Vec<[u8; 3]> {
    let top = img.height() - strip_height(img.width() as usize) as u32;
    let mut c: Vec<[u8; 3]> = (top..img.height()).flat_map(|y| (0..img.width()).map(move |x| (x, y))).map(|(x, y)| img.get_pixel(x, y).0).collect();
    c.sort();
    c.dedup();
    c
}

#[test]
fn reference_samples_0_skips_the_reference_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let (out, t) = ssr(dir.path(), &["--reference-samples", "0"]);
    assert!(t.contains("reference: skipped (--reference-samples 0)"), "{t}");
    assert!(t.contains("frame total"), "{t}");
    assert!(!t.contains("error vs reference"), "{t}");
    let exr = read_exr(&out).unwrap();
    assert!(exr.channel("reference_all.R").is_err(), "reference channels written without a reference");
    for f in ["reference.png", "error.png", "lit_reference.png"] {
        assert!(!beside(&out, f).exists(), "{f} written without a reference");
    }
    assert!(beside(&out, "lit.exr").exists() && beside(&out, "lit.png").exists());
}

/// Every run prints each pass, their total and the reference's own time; the lit frame is scene
/// colour + specular; where no reflection is traced the SSR composite and the reference show the
/// same fallback (the sky) and the two lit frames are equal.
#[test]
fn times_lit_frame_and_one_convention_for_untraced_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let (out, t) = ssr(dir.path(), &["--reference-samples", "4"]);
    let total_line = t.lines().find(|l| l.trim_start().starts_with("frame total")).unwrap_or_else(|| panic!("no frame total: {t}"));
    let ms = |l: &str| -> f64 { l.split_whitespace().find_map(|w| w.parse::<f64>().ok()).unwrap() };
    let passes: f64 = t.lines().filter(|l| l.contains(" ms (") && !l.contains("frame total")).map(ms).sum();
    let total = ms(total_line.trim_start().trim_start_matches("frame total"));
    assert!((total - passes).abs() <= 0.01 * passes.max(1.0), "frame total {total} ms, passes add up to {passes} ms\n{t}");
    let ref_line = t.lines().find(|l| l.trim_start().starts_with("reference: ")).unwrap_or_else(|| panic!("no reference time: {t}"));
    assert!(ref_line.contains(" s (4 rays per glossy pixel"), "{ref_line}");

    let main = read_exr(&out).unwrap();
    let spec = read_exr(&beside(&out, "specular.exr")).unwrap();
    let lit = read_exr(&beside(&out, "lit.exr")).unwrap();
    let hit = main.channel("hit").unwrap();
    let untraced: Vec<usize> = (0..N * N).filter(|&i| hit[i] < 0.0).collect();
    let traced = N * N - untraced.len();
    assert!(untraced.len() > 200 && traced > 200, "{} untraced pixels", untraced.len());
    for c in ["R", "G", "B"] {
        let comp = main.channel(&format!("composite.{c}")).unwrap();
        let reference = main.channel(&format!("reference_all.{c}")).unwrap();
        let same = untraced.iter().filter(|&&i| comp[i] == reference[i]).count();
        assert!(same as f64 >= 0.99 * untraced.len() as f64, "{c}: composite = reference on {same} of {} untraced pixels", untraced.len());
        let (l, lr, s) = (lit.channel(c).unwrap(), lit.channel(&format!("reference.{c}")).unwrap(), spec.channel(c).unwrap());
        let same = untraced.iter().filter(|&&i| l[i] == lr[i]).count();
        assert!(same as f64 >= 0.99 * untraced.len() as f64, "{c}: lit frames equal on {same} of {} untraced pixels", untraced.len());
        // Lit = colour + specular: at least the specular, and more on traced pixels (the colour).
        assert!((0..N * N).all(|i| l[i] >= s[i]), "{c}: lit frame below its specular term");
        assert!((0..N * N).filter(|&i| hit[i] >= 0.0).any(|i| l[i] > s[i] && s[i] > 0.0), "{c}: no pixel has both colour and specular");
    }
}

/// Debug images carry a legend strip; the step counts use the fixed scale of the iteration limit;
/// hit fractions the fixed [0, 1] scale with a "no ray" colour; tiles one swatch per class.
#[test]
fn debug_images_have_legends_and_fixed_scales() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = ssr(dir.path(), &["--reference-samples", "1", "--max-steps", "200"]);
    let main = read_exr(&out).unwrap();
    let (hit, steps) = (main.channel("hit").unwrap(), main.channel("steps").unwrap());
    for f in ["hit.png", "steps.png", "error.png"] {
        let img = png(&beside(&out, f));
        // enlarged k times so the image spans the legend's width (no blank strip beside it)
        let k = legend::scale(N);
        assert!(k > 1 && N * k >= legend::MIN_WIDTH, "{f}");
        assert_eq!((img.width() as usize, img.height() as usize), (N * k, N * k + strip_height(N * k)), "{f}: no legend strip");
        let c = strip_colours(&img);
        for want in [colormap(0.0), colormap(1.0), NO_VALUE] {
            assert!(c.contains(&want), "{f}: legend lacks {want:?}");
        }
    }
    let (hp, sp) = (png(&beside(&out, "hit.png")), png(&beside(&out, "steps.png")));
    let k = legend::scale(N) as u32;
    let max_steps = steps.iter().cloned().fold(0.0f32, f32::max);
    assert!(max_steps < 200.0, "no ray should need 200 iterations at 64x64: {max_steps}");
    for i in 0..N * N {
        let (x, y) = ((i % N) as u32, (i / N) as u32);
        let (want_h, want_s) = if hit[i] < 0.0 { (NO_VALUE, NO_VALUE) } else { (legend::ramp(hit[i], 0.0, 1.0), legend::ramp(steps[i], 0.0, 200.0)) };
        // every pixel of the pixel's k x k block
        for (dx, dy) in [(0, 0), (k - 1, 0), (0, k - 1), (k - 1, k - 1)] {
            assert_eq!(hp.get_pixel(x * k + dx, y * k + dy).0, want_h, "hit.png pixel {x},{y} (hit {})", hit[i]);
            assert_eq!(sp.get_pixel(x * k + dx, y * k + dy).0, want_s, "steps.png pixel {x},{y} (steps {})", steps[i]);
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = ssr(dir.path(), &["--pipeline", "sssr", "--reference-samples", "0"]);
    let tiles = png(&beside(&out, "tiles.png"));
    let c = strip_colours(&tiles);
    for k in 0..4 {
        assert!(c.contains(&colormap(k as f32 / 3.0)), "tiles legend lacks class {k}");
    }
}
