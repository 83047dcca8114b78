// `host bench storage`, table rows: what reading a small table at per-invocation addresses costs
// (the pattern of the energy LUT taps in the specular pass), with the table in a storage buffer
// or in a uniform buffer. Invocation i reads 16 floats at addresses (16 i + 977 j) mod 16384 of a
// 64 KiB table and writes their sum. SPACE and PREFIX are filled in by the host.

struct Args { invocations: u32, groups_x: u32 }

@group(0) @binding(0) var<storage, read> args: Args;
@group(0) @binding(1) var<SPACE> table: array<vec4<f32>, 4096>;
@group(0) @binding(2) var<storage, read_write> output: array<f32>;

@compute @workgroup_size(64)
fn PREFIX_table_16(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * args.groups_x * 64u;
    if (i >= args.invocations) { return; }
    var s = 0.0;
    for (var j = 0u; j < 16u; j++) {
        let a = (i * 16u + j * 977u) & 16383u;
        s += table[a >> 2u][a & 3u];
    }
    output[i] = s;
}
