//! The functions `host eval` can evaluate over a table of rows, each declared once with
//! [`evaluable!`]: its name, summary, typed input and output columns, and body.
//!
//! From that one declaration the macro generates, per function `f`, a module `f` holding
//! - `IN` / `OUT`: the number of f32 columns it reads and writes,
//! - `row(x, xb, y, yb)`: the per-invocation function both backends call (inputs from `x[xb..]`,
//!   outputs to `y[yb..]`, one bounds check for the whole row),
//! - `kernel`: its own `#[spirv(compute)]` entry point (entry name `eval::<group>::f::kernel`),
//! - `INFO`: its registry entry ([`FunctionInfo`]: column names, entry point, CPU batch loop),
//!
//! and the group's `FUNCTIONS` list. Column names come from the parameter names and types of the
//! declaration (`wm: Vec3` is `wm_x, wm_y, wm_z`; `f: Rgb` is `f_r, f_g, f_b`; `d: f32` is `d`),
//! so the names a user writes and the values the body reads cannot drift apart. Directions are
//! in the local shading frame (normal = +z).

pub mod basic;
pub mod bxdf;
pub mod microfacet;
pub mod vndf;

/// The argument record of every eval entry point (binding 0): rows in this dispatch and
/// workgroups in x of the 2D dispatch (rows are numbered `x + y * groups_x * WORKGROUP_SIZE`).
/// Shared by the host (as a `bytemuck::Pod`) and the kernels.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct EvalArgs {
    pub rows: u32,
    pub groups_x: u32,
}

/// One evaluable function, as `host eval`, the benches and the cross-checks see it.
#[cfg(not(target_arch = "spirv"))]
#[derive(Clone, Copy, Debug)]
pub struct FunctionInfo {
    /// The name users pass to `host eval`.
    pub name: &'static str,
    /// What it computes, with the paper and equation.
    pub summary: &'static str,
    /// The group it is declared in (`basic`, `microfacet`, `bxdf`, `vndf`).
    pub group: &'static str,
    /// Input column names, in the order the body reads them.
    pub inputs: &'static [&'static str],
    /// Output column names, in the order the body writes them.
    pub outputs: &'static [&'static str],
    /// The SPIR-V entry point that evaluates it (one per function).
    pub entry: &'static str,
    /// The CPU batch loop: whole rows of `inputs.len()` values in, whole rows of
    /// `outputs.len()` values out (the slices hold the same number of rows).
    pub cpu_rows: fn(&[f32], &mut [f32]),
}

/// Every group's functions, in listing order.
#[cfg(not(target_arch = "spirv"))]
pub const GROUPS: &[&[FunctionInfo]] = &[basic::FUNCTIONS, microfacet::FUNCTIONS, bxdf::FUNCTIONS, vndf::FUNCTIONS];

/// Every evaluable function.
#[cfg(not(target_arch = "spirv"))]
pub fn functions() -> impl Iterator<Item = &'static FunctionInfo> {
    GROUPS.iter().flat_map(|g| g.iter())
}

/// Look a function up by name.
#[cfg(not(target_arch = "spirv"))]
pub fn find(name: &str) -> Option<&'static FunctionInfo> {
    functions().find(|f| f.name == name)
}

/// Column helpers of [`evaluable!`]: width, Rust type, read and write per column type.
#[doc(hidden)]
#[macro_export]
macro_rules! eval_col {
    (width f32) => { 1usize };
    (width Vec3) => { 3usize };
    (width Rgb) => { 3usize };
    (ty f32) => { f32 };
    (ty Vec3) => { shader_core::Vec3 };
    (ty Rgb) => { shader_core::Vec3 };
    // SAFETY (callers): `at + width <= x.len()` is checked once per row in `row`.
    (read f32, $x:ident, $at:expr) => { unsafe { *$x.get_unchecked($at) } };
    (read Vec3, $x:ident, $at:expr) => {
        unsafe { shader_core::Vec3::new(*$x.get_unchecked($at), *$x.get_unchecked($at + 1), *$x.get_unchecked($at + 2)) }
    };
    (read Rgb, $x:ident, $at:expr) => { $crate::eval_col!(read Vec3, $x, $at) };
    (write f32, $y:ident, $at:expr, $v:expr) => { unsafe { *$y.get_unchecked_mut($at) = $v } };
    (write Vec3, $y:ident, $at:expr, $v:expr) => {{
        let v = $v;
        unsafe {
            *$y.get_unchecked_mut($at) = v.x;
            *$y.get_unchecked_mut($at + 1) = v.y;
            *$y.get_unchecked_mut($at + 2) = v.z;
        }
    }};
    (write Rgb, $y:ident, $at:expr, $v:expr) => { $crate::eval_col!(write Vec3, $y, $at, $v) };
}

/// Column names of a typed parameter list (a token muncher: `a: f32, w: Vec3` ->
/// `["a", "w_x", "w_y", "w_z"]`).
#[doc(hidden)]
#[macro_export]
macro_rules! eval_names {
    (@acc [$($out:expr),*]) => { &[$($out),*] };
    (@acc [$($out:expr),*] $n:ident : f32 $(, $($rest:tt)*)?) => {
        $crate::eval_names!(@acc [$($out,)* stringify!($n)] $($($rest)*)?)
    };
    (@acc [$($out:expr),*] $n:ident : Vec3 $(, $($rest:tt)*)?) => {
        $crate::eval_names!(@acc [$($out,)* concat!(stringify!($n), "_x"), concat!(stringify!($n), "_y"), concat!(stringify!($n), "_z")] $($($rest)*)?)
    };
    (@acc [$($out:expr),*] $n:ident : Rgb $(, $($rest:tt)*)?) => {
        $crate::eval_names!(@acc [$($out,)* concat!(stringify!($n), "_r"), concat!(stringify!($n), "_g"), concat!(stringify!($n), "_b")] $($($rest)*)?)
    };
    ($($t:tt)*) => { $crate::eval_names!(@acc [] $($t)*) };
}

/// Declare evaluable functions: one row per function,
///
/// ```text
/// name "summary (paper, equation)" (input: Type, ...) -> (output: Type, ...) { body }
/// ```
///
/// with column types `f32`, `Vec3` (`_x,_y,_z`) and `Rgb` (`_r,_g,_b`, a `Vec3` in the body).
/// The body sees the inputs as variables of those names and evaluates to the output (one
/// output) or a tuple of outputs in declaration order. See the module documentation for what is
/// generated.
#[macro_export]
macro_rules! evaluable {
    (group = $group:literal; $(
        $name:ident $summary:literal ($($i:ident : $it:ident),* $(,)?) -> ($($o:ident : $ot:ident),+ $(,)?) $body:block
    )*) => {
        $(
            #[doc = $summary]
            #[allow(non_snake_case, clippy::all)]
            pub mod $name {
                #[allow(unused_imports)]
                use super::*;
                #[allow(unused_imports)]
                use spirv_std::spirv;

                /// f32 values per input row.
                pub const IN: usize = 0 $(+ $crate::eval_col!(width $it))*;
                /// f32 values per output row.
                pub const OUT: usize = 0 $(+ $crate::eval_col!(width $ot))+;

                /// The function itself, on typed values.
                #[inline(always)]
                #[allow(unused_parens, clippy::too_many_arguments)]
                pub fn eval($($i: $crate::eval_col!(ty $it)),*) -> ($($crate::eval_col!(ty $ot)),+) $body

                /// Evaluate the row at `x[xb..xb + IN]` into `y[yb..yb + OUT]`; a row that does
                /// not fit either slice is skipped (one bounds check per row).
                #[inline(always)]
                #[allow(unused_assignments, unused_mut, unused_parens, unused_variables)]
                pub fn row(x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
                    if xb + IN > x.len() || yb + OUT > y.len() {
                        return;
                    }
                    let mut at = xb;
                    $(
                        let $i = $crate::eval_col!(read $it, x, at);
                        at += $crate::eval_col!(width $it);
                    )*
                    let ($($o),+) = eval($($i),*);
                    let mut at = yb;
                    $(
                        $crate::eval_col!(write $ot, y, at, $o);
                        at += $crate::eval_col!(width $ot);
                    )+
                }

                /// The compute entry point: one row per invocation.
                #[spirv(compute(threads(64)))]
                pub fn kernel(
                    #[spirv(global_invocation_id)] id: spirv_std::glam::UVec3,
                    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &$crate::eval::EvalArgs,
                    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] input: &[f32],
                    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] output: &mut [f32],
                ) {
                    if let Some(r) = $crate::invocation_index(id, args.rows, args.groups_x) {
                        row(input, r as usize * IN, output, r as usize * OUT);
                    }
                }

                /// The CPU batch loop over whole rows.
                #[cfg(not(target_arch = "spirv"))]
                pub fn cpu_rows(x: &[f32], y: &mut [f32]) {
                    let rows = if IN > 0 { x.len() / IN } else { y.len() / OUT };
                    for r in 0..rows {
                        row(x, r * IN, y, r * OUT);
                    }
                }

                /// Its registry entry.
                #[cfg(not(target_arch = "spirv"))]
                pub const INFO: $crate::eval::FunctionInfo = $crate::eval::FunctionInfo {
                    name: stringify!($name),
                    summary: $summary,
                    group: $group,
                    inputs: $crate::eval_names!($($i : $it),*),
                    outputs: $crate::eval_names!($($o : $ot),+),
                    entry: concat!("eval::", $group, "::", stringify!($name), "::kernel"),
                    cpu_rows,
                };
            }
        )*

        /// The functions declared in this group, in declaration order.
        #[cfg(not(target_arch = "spirv"))]
        pub const FUNCTIONS: &[$crate::eval::FunctionInfo] = &[$($name::INFO),*];
    };
}
