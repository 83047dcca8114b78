// Hand-written WGSL versions of two kernels, for the benches' speed reference only: the same
// formulas as shader_core::ndf::ggx_d and shader_core::vndf::sample_vndf_heitz, the same row
// layout and argument record as the rust-gpu eval entry points (shader_kernels::eval), compiled
// by naga. Not bit-exact (the driver's sin/cos/sqrt/division, no NoContraction): the benches
// compare their rate with the rust-gpu kernels', never their values.

struct EvalArgs { rows: u32, groups_x: u32 }

@group(0) @binding(0) var<storage, read> args: EvalArgs;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read_write> output: array<f32>;

const PI: f32 = 3.14159265358979;

fn row_of(id: vec3<u32>) -> u32 {
    return id.x + id.y * args.groups_x * 64u;
}

fn finite3(v: vec3<f32>) -> bool {
    let a = abs(v);
    return a.x <= 3.4028235e38 && a.y <= 3.4028235e38 && a.z <= 3.4028235e38;
}

fn alpha_valid(ax: f32, ay: f32) -> bool {
    return ax >= 0.0 && ay >= 0.0 && ax <= 3.4028235e38 && ay <= 3.4028235e38;
}

fn ggx_d(wm_in: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (!alpha_valid(ax, ay) || !finite3(wm_in)) {
        return bitcast<f32>(0x7fc00000u);
    }
    if (wm_in.z <= 0.0 || ax == 0.0 || ay == 0.0) {
        return 0.0;
    }
    // Power-of-two rescale so the largest component is in [1, 2), as pow2_rescaled does.
    let m = max(max(abs(wm_in.x), abs(wm_in.y)), abs(wm_in.z));
    let e = (bitcast<u32>(m) >> 23u) & 0xffu;
    let wm = wm_in * bitcast<f32>((254u - e) << 23u);
    let sx = wm.x / ax;
    let sy = wm.y / ay;
    let q = sx * sx + sy * sy + wm.z * wm.z;
    let len2 = dot(wm, wm);
    let r = len2 / q;
    return r * r / (PI * ax * ay);
}

@compute @workgroup_size(64)
fn wgsl_ggx_d(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = row_of(id);
    if (r >= args.rows) {
        return;
    }
    let b = r * 5u;
    let wm = vec3<f32>(input[b], input[b + 1u], input[b + 2u]);
    output[r] = ggx_d(wm, input[b + 3u], input[b + 4u]);
}

@compute @workgroup_size(64)
fn wgsl_sample_vndf_heitz(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = row_of(id);
    if (r >= args.rows) {
        return;
    }
    let b = r * 7u;
    let wi = vec3<f32>(input[b], input[b + 1u], input[b + 2u]);
    let ax = input[b + 3u];
    let ay = input[b + 4u];
    let u1 = input[b + 5u];
    let u2 = input[b + 6u];
    let o = r * 4u;
    if (!alpha_valid(ax, ay) || !finite3(wi) || dot(wi, wi) <= 0.0) {
        let nan = bitcast<f32>(0x7fc00000u);
        output[o] = nan;
        output[o + 1u] = nan;
        output[o + 2u] = nan;
        output[o + 3u] = nan;
        return;
    }
    let len2 = (ax * wi.x) * (ax * wi.x) + (ay * wi.y) * (ay * wi.y);
    if (len2 == 0.0 && wi.z <= 0.0) {
        output[o] = 0.0;
        output[o + 1u] = 0.0;
        output[o + 2u] = 0.0;
        output[o + 3u] = 0.0;
        return;
    }
    let vh = normalize(vec3<f32>(ax * wi.x, ay * wi.y, wi.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if (lensq > 0.0) {
        let inv = 1.0 / sqrt(lensq);
        t1 = vec3<f32>(-vh.y * inv, vh.x * inv, 0.0);
    }
    let t2 = cross(vh, t1);
    let rr = sqrt(u1);
    let phi = 2.0 * PI * u2;
    let p1 = rr * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let w2 = 1.0 - p1 * p1;
    var w = 0.0;
    if (w2 > 0.0) {
        w = sqrt(w2);
    }
    let p2 = (1.0 - s) * w + s * (rr * sin(phi));
    let q = 1.0 - p1 * p1 - p2 * p2;
    var pz = 0.0;
    if (q > 0.0) {
        pz = sqrt(q);
    }
    let nh = t1 * p1 + t2 * p2 + vh * pz;
    let wm = normalize(vec3<f32>(ax * nh.x, ay * nh.y, max(nh.z, 0.0)));
    let wo = 2.0 * dot(wi, wm) * wm - wi;
    let d = ggx_d(wm, ax, ay);
    var pdf = 0.0;
    if (d != 0.0) {
        let t = sqrt(len2 + wi.z * wi.z);
        if (wi.z >= 0.0) {
            pdf = d / (2.0 * (wi.z + t));
        } else {
            pdf = d * (t - wi.z) / (2.0 * len2);
        }
    }
    output[o] = wo.x;
    output[o + 1u] = wo.y;
    output[o + 2u] = wo.z;
    output[o + 3u] = pdf;
}
