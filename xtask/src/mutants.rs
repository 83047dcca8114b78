//! `cargo xtask mutants`: each formula test must fail when the formula it checks is changed. A
//! mutant replaces one exact piece of source (found exactly once) with a wrong formula, runs the
//! CPU-side test meant to catch it, and restores the file (also on error or panic); a mutant the
//! test does not catch, or one whose source piece is no longer there, fails the command.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// One wrong formula and the test that must catch it.
pub struct Mutant {
    pub name: &'static str,
    /// Source file, relative to the workspace root.
    pub file: &'static str,
    /// The exact source piece replaced (it must occur exactly once in `file`).
    pub from: &'static str,
    pub to: &'static str,
    /// `cargo test -p <package> --test <test> [-- <filter>...]`: CPU-side tests only (the
    /// mutated kernels no longer match the committed SPIR-V, so a GPU comparison would fail for
    /// that reason alone).
    pub package: &'static str,
    pub test: &'static str,
    pub filter: &'static [&'static str],
}

const STOCHASTIC: &str = "shader-core/src/ssr/stochastic.rs";
const RESOLVE: &str = "shader-core/src/ssr/resolve.rs";

const IEEE: &str = "shader-core/src/ieee.rs";

pub const MUTANTS: &[Mutant] = &[
    Mutant {
        name: "division seed corrected by a quarter of its residual",
        file: IEEE,
        from: "let q = q0 + (r0 * y);",
        to: "let q = q0 + (r0 * (0.25 * y));",
        package: "shader-core",
        test: "ieee_exhaustive",
        filter: &["div_perturbed_seeds_sample"],
    },
    Mutant {
        name: "division's last bit against the whole spacing below, not the midpoint",
        file: IEEE,
        from: "let below = (2.0 * r1) < -(dn * xb);",
        to: "let below = r1 < -(dn * xb);",
        package: "shader-core",
        test: "ieee_exhaustive",
        filter: &["div_perturbed_seeds_sample"],
    },
    Mutant {
        name: "square-root seed corrected by half its residual",
        file: IEEE,
        from: "let s = s0 + (r0 * (0.5 * y));",
        to: "let s = s0 + (r0 * (0.25 * y));",
        package: "shader-core",
        test: "ieee_exhaustive",
        filter: &["sqrt_perturbed_seeds_all_significands"],
    },
    Mutant {
        name: "texture transform rotated the wrong way",
        file: "scene/src/lib.rs",
        from: "[(c * sx) as f32, (s * sy) as f32, self.offset[0], (-s * sx) as f32, (c * sy) as f32, self.offset[1]]",
        to: "[(c * sx) as f32, (-s * sy) as f32, self.offset[0], (s * sx) as f32, (c * sy) as f32, self.offset[1]]",
        package: "host",
        test: "render_scene",
        filter: &["texture_transform"],
    },
    Mutant {
        name: "stochastic ray weight without G2",
        file: STOCHASTIC,
        from: "ieee::div(ieee::div(ggx_d_cos(s.n.dot(h), alpha) * g2, 4.0 * nv), pdf)",
        to: "ieee::div(ieee::div(ggx_d_cos(s.n.dot(h), alpha) + 0.0 * g2, 4.0 * nv), pdf)",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["stochastic_ray_weight"],
    },
    Mutant {
        name: "stochastic ray weight not divided by the pdf",
        file: STOCHASTIC,
        from: "let w = ieee::div(ieee::div(ggx_d_cos(s.n.dot(h), alpha) * g2, 4.0 * nv), pdf);",
        to: "let w = ieee::div(ggx_d_cos(s.n.dot(h), alpha) * g2, 4.0 * nv);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["stochastic_ray_weight"],
    },
    Mutant {
        name: "temporal weight 1 / (2 (n + 1))",
        file: STOCHASTIC,
        from: "let w = maxf(ieee::div(1.0, n1), p.temporal_alpha);",
        to: "let w = maxf(ieee::div(0.5, n1), p.temporal_alpha);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["temporal_blend"],
    },
    Mutant {
        name: "FIS mip of twice the footprint",
        file: STOCHASTIC,
        from: "maxf(0.0, log2_approx(2.0 * dist_px * tan_half))",
        to: "maxf(0.0, log2_approx(4.0 * dist_px * tan_half))",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["fis_cone_and_mip"],
    },
    Mutant {
        name: "FIS cone without 1/pi",
        file: STOCHASTIC,
        from: "ieee::sqrt(ieee::div(core::f32::consts::FRAC_1_PI, pdf * rays_in_window))",
        to: "ieee::sqrt(ieee::div(1.0, pdf * rays_in_window))",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["fis_cone_and_mip"],
    },
    Mutant {
        name: "virtual image in front of the surface",
        file: STOCHASTIC,
        from: "let virt = s.pos + s.pos * (ieee::div(dist, len));",
        to: "let virt = s.pos - s.pos * (ieee::div(dist, len));",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["virtual_image"],
    },
    Mutant {
        name: "neighbourhood resolves without the roughness fade",
        file: RESOLVE,
        from: "    let k = ieee::div(fade, acc_w);",
        to: "    let k = ieee::div(1.0 + 0.0 * fade, acc_w);",
        package: "crosscheck",
        test: "ssr_hits",
        filter: &[],
    },
    Mutant {
        name: "GetSSRSampleWeight without Lambda(l)",
        file: RESOLVE,
        from: "ieee::div(lambda_v_plus_one, lambda_v_plus_one + lambda_l)",
        to: "ieee::div(lambda_v_plus_one, lambda_v_plus_one + 0.0 * lambda_l)",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["hdrp_sample_weight"],
    },
    Mutant {
        name: "bilinear sample weighs x by the y fraction",
        file: RESOLVE,
        from: "let top = lerp3(texel(p, pyr, off, w, x0, y0), texel(p, pyr, off, w, x1, y0), fx);",
        to: "let top = lerp3(texel(p, pyr, off, w, x0, y0), texel(p, pyr, off, w, x1, y0), fy);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["colour_samples_are_bilinear"],
    },
    Mutant {
        name: "trilinear sample with the mip fraction reversed",
        file: RESOLVE,
        from: "lerp3(c0, c1, f)",
        to: "lerp3(c0, c1, 1.0 - f)",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["colour_samples_are_linear_between_mips"],
    },
    Mutant {
        name: "edge-of-screen fade on x only",
        file: RESOLVE,
        from: "smoothstep01(tx) * smoothstep01(ty)",
        to: "smoothstep01(tx) + 0.0 * smoothstep01(ty)",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["edge_of_screen_fade"],
    },
    Mutant {
        name: "SSR_APPROX mip from 1 - roughness",
        file: RESOLVE,
        from: "let mip = lerp(0.0, p.color_max_mip as f32, rough);",
        to: "let mip = lerp(0.0, p.color_max_mip as f32, 1.0 - rough);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["ssr_approx"],
    },
    Mutant {
        name: "SSR_APPROX without the roughness fade",
        file: RESOLVE,
        from: "    let opacity = edge_of_screen_fade(u, v, p.edge_fade_rcp_length)\n        * perceptual_roughness_fade(rough, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length);",
        to: "    let opacity = edge_of_screen_fade(u, v, p.edge_fade_rcp_length);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["ssr_approx"],
    },
    Mutant {
        name: "hit reprojection adds the motion vector",
        file: RESOLVE,
        from: "let u = ieee::div(hx, p.width as f32) - load(gbuf, b + gbuf::MOTION);",
        to: "let u = ieee::div(hx, p.width as f32) + load(gbuf, b + gbuf::MOTION);",
        package: "crosscheck",
        test: "ssr_formulas",
        filter: &["ssr_approx"],
    },
    Mutant {
        name: "specular FG with E and E' swapped",
        file: "shader-core/src/ssr/specular.rs",
        from: "Vec3::new(schlick_albedo(e, ep, f0.x, 1.0), schlick_albedo(e, ep, f0.y, 1.0), schlick_albedo(e, ep, f0.z, 1.0))",
        to: "Vec3::new(schlick_albedo(ep, e, f0.x, 1.0), schlick_albedo(ep, e, f0.y, 1.0), schlick_albedo(ep, e, f0.z, 1.0))",
        package: "crosscheck",
        test: "ssr_specular",
        filter: &["fg_term_matches_f64_quadrature"],
    },
    Mutant {
        name: "height-correlated G2 as 1 / (1 + Lambda_o Lambda_i)",
        file: "shader-core/src/masking.rs",
        from: "ieee::div(1.0, 1.0 + (lambda_o + lambda_i))",
        to: "ieee::div(1.0, 1.0 + lambda_o * lambda_i)",
        package: "crosscheck",
        test: "microfacet_properties",
        filter: &["white_furnace"],
    },
    Mutant {
        name: "Schlick weight (1 - c)^4",
        file: "shader-core/src/fresnel.rs",
        from: "    m2 * m2 * m\n}",
        to: "    m2 * m2 + 0.0 * m\n}",
        package: "crosscheck",
        test: "bxdf_properties",
        filter: &["schlick_endpoints_and_shape"],
    },
    Mutant {
        name: "Heitz 2018 VNDF sample with the hemisphere blend reversed",
        file: "shader-core/src/vndf.rs",
        from: "let p2 = (1.0 - s) * w + s * p2;",
        to: "let p2 = s * w + (1.0 - s) * p2;",
        package: "crosscheck",
        test: "vndf_chi2",
        filter: &["chi2_sample_vndf_heitz"],
    },
    Mutant {
        name: "Kulla-Conty f_ms with F_avg instead of F_avg^2",
        file: "shader-core/src/energy.rs",
        from: "ieee::div((1.0 - e_o) * (1.0 - e_i) * (f_avg * f_avg * e_avg), PI * loss * (1.0 - f_avg * loss))",
        to: "ieee::div((1.0 - e_o) * (1.0 - e_i) * (f_avg * e_avg), PI * loss * (1.0 - f_avg * loss))",
        package: "crosscheck",
        test: "energy_properties",
        filter: &["furnace_albedo_is_one_with_compensation"],
    },
    Mutant {
        name: "Turquin scale as for F0 = 1",
        file: "shader-core/src/energy.rs",
        from: "    1.0 + f0 * (ieee::div(1.0, e_o) - 1.0)",
        to: "    1.0 + (ieee::div(1.0, e_o) - 1.0) + 0.0 * f0",
        package: "host",
        test: "render_analytic",
        filter: &["white_furnace_coloured_metal"],
    },
    Mutant {
        name: "light-sampling pdf without the cosine at the light",
        file: "shader-core/src/pt/light.rs",
        from: "ieee::div(d2, cos_l * area)",
        to: "ieee::div(d2, area)",
        package: "host",
        test: "render_analytic",
        filter: &["mis_bsdf_and_light_sampling_agree"],
    },
    Mutant {
        name: "next-event estimation without its MIS weight",
        file: "shader-core/src/pt/integrator.rs",
        from: "{ 1.0 } else { power_heuristic(p_light, mat.pdf(wo, wi)) };",
        to: "{ 1.0 } else { 1.0 + 0.0 * power_heuristic(p_light, mat.pdf(wo, wi)) };",
        package: "host",
        test: "render_analytic",
        filter: &["area_lights_agree"],
    },
    Mutant {
        name: "emitter hit by a BSDF sample without its MIS weight",
        file: "shader-core/src/pt/integrator.rs",
        from: "                power_heuristic(prev_pdf, pl)\n",
        to: "                1.0 + 0.0 * power_heuristic(prev_pdf, pl)\n",
        package: "host",
        test: "render_analytic",
        filter: &["area_lights_agree"],
    },
    Mutant {
        name: "next-event estimation without the cosine at the surface",
        file: "shader-core/src/pt/integrator.rs",
        from: "ieee::div(wi.z.abs() * w, p_light)",
        to: "ieee::div(w, p_light)",
        package: "host",
        test: "render_analytic",
        filter: &["directional_light_on_a_plane_is_f_cos_e"],
    },
];

/// Where the original of the file being mutated is kept while its mutant runs: a run that is
/// killed (Ctrl-C) cannot restore it, so the next run does, first thing.
fn backup_dir(root: &Path) -> PathBuf {
    root.join("target").join("mutants-backup")
}

/// Puts a file's original text back when dropped, and removes its backup.
struct Restore {
    path: PathBuf,
    text: String,
    backup: PathBuf,
}

impl Restore {
    /// Back up `file` (relative to `root`) and return its guard.
    fn new(root: &Path, file: &str) -> Result<Restore> {
        let path = root.join(file);
        let text = std::fs::read_to_string(&path).with_context(|| file.to_string())?;
        let dir = backup_dir(root);
        std::fs::create_dir_all(&dir)?;
        let backup = dir.join(file.replace('/', "__"));
        std::fs::write(&backup, &text).with_context(|| format!("backing up {file}"))?;
        Ok(Restore { path, text, backup })
    }
}

impl Drop for Restore {
    fn drop(&mut self) {
        match std::fs::write(&self.path, &self.text) {
            Ok(()) => {
                let _ = std::fs::remove_file(&self.backup);
            }
            Err(e) => eprintln!("[mutants] could not restore {} (its original is in {}): {e}", self.path.display(), self.backup.display()),
        }
    }
}

/// Restore the files an interrupted run left mutated.
fn restore_interrupted(root: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(backup_dir(root)) else { return Ok(()) };
    for e in entries {
        let e = e?;
        let file = e.file_name().to_string_lossy().replace("__", "/");
        std::fs::write(root.join(&file), std::fs::read(e.path())?).with_context(|| format!("restoring {file}"))?;
        std::fs::remove_file(e.path())?;
        eprintln!("[mutants] restored {file}, left mutated by an interrupted run");
    }
    Ok(())
}

/// Build the mutant's test binary (an error if it does not compile: a mutant must be a wrong
/// formula, not a broken build) and run its filtered tests; true if they pass.
fn cargo_test(root: &Path, m: &Mutant) -> Result<bool> {
    let cargo = |run: bool| {
        let mut cmd = Command::new(env!("CARGO"));
        cmd.current_dir(root).args(["test", "--release", "-q", "-p", m.package, "--test", m.test]);
        if run {
            cmd.arg("--").args(m.filter);
        } else {
            cmd.arg("--no-run");
        }
        // The tests' own GPU checks are not among the filtered ones; keep CI=true from turning a
        // skipped comparison into a failure that would look like a caught mutant.
        cmd.env_remove("CI").stdout(std::process::Stdio::null()).stderr(std::process::Stdio::null());
        cmd.status().with_context(|| format!("running cargo test -p {} --test {}", m.package, m.test))
    };
    if !cargo(false)?.success() {
        bail!("mutant {:?}: `cargo test -p {} --test {} --no-run` fails (a mutant must compile)", m.name, m.package, m.test);
    }
    Ok(cargo(true)?.success())
}

/// Run the mutants whose name contains `only` (all when empty); fails unless each test passes on
/// the unchanged source and fails on every mutant of it.
pub fn run(root: &Path, only: &str) -> Result<()> {
    restore_interrupted(root)?;
    let chosen: Vec<&Mutant> = MUTANTS.iter().filter(|m| m.name.contains(only)).collect();
    if chosen.is_empty() {
        bail!("no mutant's name contains {only:?}");
    }
    for m in &chosen {
        let text = std::fs::read_to_string(root.join(m.file)).with_context(|| m.file.to_string())?;
        let n = text.matches(m.from).count();
        if n != 1 {
            bail!("mutant {:?}: its source piece occurs {n} times in {} (it must occur once; update xtask/src/mutants.rs with the formula's new text)", m.name, m.file);
        }
    }
    // Each distinct test once, in the list's order (mutants sharing a test need not be adjacent).
    let mut tests: Vec<(&str, &str, &[&str])> = Vec::new();
    for m in &chosen {
        let t = (m.package, m.test, m.filter);
        if !tests.contains(&t) {
            tests.push(t);
        }
    }
    for (package, test, filter) in tests {
        let m = chosen.iter().find(|m| (m.package, m.test, m.filter) == (package, test, filter)).expect("listed above");
        eprintln!("[mutants] unchanged source: -p {package} --test {test} {filter:?}");
        if !cargo_test(root, m)? {
            bail!("the test `-p {package} --test {test} -- {}` fails on the unchanged source", filter.join(" "));
        }
    }
    let mut survived = Vec::new();
    println!("| mutant | file | test | caught | seconds |\n| --- | --- | --- | --- | ---: |");
    for m in &chosen {
        let start = Instant::now();
        let caught = {
            let restore = Restore::new(root, m.file)?;
            std::fs::write(&restore.path, restore.text.replacen(m.from, m.to, 1))?;
            !cargo_test(root, m)?
        };
        println!("| {} | `{}` | `{}` `{}` {} | {} | {:.0} |", m.name, m.file, m.package, m.test, m.filter.join(" "), if caught { "yes" } else { "**no**" }, start.elapsed().as_secs_f64());
        if !caught {
            survived.push(m.name);
        }
    }
    if !survived.is_empty() {
        bail!("{} of {} mutants survived their tests: {}", survived.len(), chosen.len(), survived.join("; "));
    }
    eprintln!("[mutants] all {} caught", chosen.len());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every mutant's source piece occurs exactly once in its file, so a refactor that rewrites a
    /// formula's text fails here, in `cargo test`, rather than late in `cargo xtask mutants`.
    #[test]
    fn every_source_piece_occurs_once() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        for m in MUTANTS {
            let text = std::fs::read_to_string(root.join(m.file)).unwrap_or_else(|e| panic!("{}: reading {}: {e}", m.name, m.file));
            assert_eq!(text.matches(m.from).count(), 1, "mutant {:?}: its source piece must occur once in {}", m.name, m.file);
            assert_ne!(m.from, m.to, "mutant {:?} changes nothing", m.name);
        }
    }
}
