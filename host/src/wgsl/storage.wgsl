// `host bench storage`: what reading a storage buffer costs the adapter, apart from any math.
// Invocation i reads K floats and writes their sum to output[i]: from its own record of K
// (input[i K + j], the layout of the SSR passes' G-buffer and ray records), or K times from
// addresses every invocation shares (input[j], as the SSR passes read their parameter record
// from a storage buffer before it became a uniform buffer). ELEM / LOAD are filled in by the
// host: f32 records for the scalar kernels, vec4<f32> for the vector ones (K / 4 loads).

struct Args { invocations: u32, groups_x: u32 }

@group(0) @binding(0) var<storage, read> args: Args;
@group(0) @binding(1) var<storage, read> input: array<ELEM>;
@group(0) @binding(2) var<storage, read_write> output: array<f32>;

fn invocation(id: vec3<u32>) -> u32 {
    return id.x + id.y * args.groups_x * 64u;
}

fn total(v: ELEM) -> f32 {
    return SUM;
}

@compute @workgroup_size(64)
fn own_1(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    output[i] = total(input[i]);
}

@compute @workgroup_size(64)
fn own_4(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let b = i * 4u;
    output[i] = total(input[b]) + total(input[b + 1u]) + total(input[b + 2u]) + total(input[b + 3u]);
}

@compute @workgroup_size(64)
fn own_16(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let b = i * 16u;
    var s = 0.0;
    for (var j = 0u; j < 16u; j++) {
        s += total(input[b + j]);
    }
    output[i] = s;
}

@compute @workgroup_size(64)
fn shared_16(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    var s = 0.0;
    for (var j = 0u; j < 16u; j++) {
        s += total(input[j]);
    }
    output[i] = s;
}
