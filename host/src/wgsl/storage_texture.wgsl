// `host bench storage`, texture rows: the reads of storage.wgsl's `own_K` kernels (invocation i
// sums floats i K .. i K + K - 1) through `textureLoad` of an R32Float texture `width` texels wide,
// float j at texel (j % width, j / width): what the same reads cost as sampled-image fetches;
// `texel4_own_K`: the same K floats from an Rgba32Float texture, four per fetch (floats 4t .. 4t + 3
// at texel (t % width, t / width)).

struct Args { invocations: u32, groups_x: u32, width: u32, pad: u32 }

@group(0) @binding(0) var<storage, read> args: Args;
@group(0) @binding(1) var input: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> output: array<f32>;

fn invocation(id: vec3<u32>) -> u32 {
    return id.x + id.y * args.groups_x * 64u;
}

fn fetch(j: u32) -> f32 {
    return textureLoad(input, vec2<u32>(j % args.width, j / args.width), 0).x;
}

@compute @workgroup_size(64)
fn texel_own_1(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    output[i] = fetch(i);
}

@compute @workgroup_size(64)
fn texel_own_4(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let b = i * 4u;
    output[i] = fetch(b) + fetch(b + 1u) + fetch(b + 2u) + fetch(b + 3u);
}

@compute @workgroup_size(64)
fn texel_own_16(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let b = i * 16u;
    var s = 0.0;
    for (var j = 0u; j < 16u; j++) {
        s += fetch(b + j);
    }
    output[i] = s;
}

fn fetch4(t: u32) -> vec4<f32> {
    return textureLoad(input, vec2<u32>(t % args.width, t / args.width), 0);
}

@compute @workgroup_size(64)
fn texel4_own_1(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let v = fetch4(i);
    output[i] = v.x + v.y + v.z + v.w;
}

@compute @workgroup_size(64)
fn texel4_own_4(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = invocation(id);
    if (i >= args.invocations) { return; }
    let b = i * 4u;
    var s = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let v = fetch4(b + j);
        s += v.x + v.y + v.z + v.w;
    }
    output[i] = s;
}
