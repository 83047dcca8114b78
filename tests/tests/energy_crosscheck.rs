//! Energy compensation kernels CPU vs GPU (0 ULP): the E / E' table and E_avg precompute (both
//! sequences, several chunks, so the host-side f64 sums of the f32 partial sums are compared too)
//! and the white furnace (spheres and table-grid layouts, every compensation mode).

use crosscheck::{assert_bits_equal, gpu_backend};
use host::energy::{self, Compensation, FurnaceConfig, Sequence, TableSpec};
use host::Backend;


#[test]
fn precompute_matches_gpu_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    for seq in [Sequence::Pcg, Sequence::Sobol] {
        let spec = TableSpec { n_mu: 16, n_r: 12, n_avg: 10, samples: 700, avg_samples: 900, chunk: 256, seq, seed: 11 };
        let (c, _) = energy::precompute(&Backend::Cpu, &spec, None).unwrap();
        let (g, _) = energy::precompute(gpu, &spec, None).unwrap();
        let tag = seq.label();
        assert_bits_equal(&format!("{tag} E"), 1, &c.e, &g.e);
        assert_bits_equal(&format!("{tag} E'"), 1, &c.e_prime, &g.e_prime);
        assert_bits_equal(&format!("{tag} E_avg"), 1, &c.e_avg, &g.e_avg);
    }
}

#[test]
fn furnace_matches_gpu_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    let spec = TableSpec { samples: 256, avg_samples: 1024, ..TableSpec::default() };
    let (t, _) = energy::precompute(&Backend::Cpu, &spec, None).unwrap();
    let lut = t.lut_buffer();
    for mode in Compensation::ALL {
        for (metallic, base, seq) in [(1.0f32, 1.0f32, Sequence::Sobol), (0.0, 0.8, Sequence::Pcg), (0.5, 0.6, Sequence::Sobol)] {
            let cfg = FurnaceConfig { mode, metallic, base, samples: 64, seq, seed: 3, min_roughness: shader_core::energy::COMPENSATION_MIN_ROUGHNESS };
            let tag = format!("{} metallic {metallic} base {base} {}", mode.label(), seq.label());
            let c = energy::furnace_spheres(&Backend::Cpu, &lut, &cfg, 5, 24).unwrap();
            let g = energy::furnace_spheres(gpu, &lut, &cfg, 5, 24).unwrap();
            assert_bits_equal(&format!("{tag} spheres"), 1, &c.data, &g.data);
            let c = energy::furnace_grid(&Backend::Cpu, &lut, &cfg, 32, 32).unwrap();
            let g = energy::furnace_grid(gpu, &lut, &cfg, 32, 32).unwrap();
            assert_bits_equal(&format!("{tag} grid"), 1, &c, &g);
        }
    }
}
