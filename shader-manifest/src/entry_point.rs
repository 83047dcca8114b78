//! One entry point's SPIR-V module cut out of a module holding many (SPIR-V 1.6 spec, 2.4 "Logical
//! Layout of a Module"): the functions the entry point calls, the globals (types, constants,
//! variables) they refer to, and only their names and decorations; the source text is left out.
//!
//! A Vulkan driver reads the whole module it is given for every pipeline it creates (Mesa's
//! `spirv_to_nir` parses every function before it drops the unused ones), so with one module of
//! a hundred entry points each pipeline's first use costs the module's size, not its own. The
//! instructions that are kept are copied word for word: the kept code, its `NoContraction`
//! decorations and execution modes are those of the module, so results do not change.

use std::collections::{HashMap, HashSet};
use std::ops::Range;

use crate::{
    instructions, spirv_string, OP_DECORATE, OP_ENTRY_POINT, OP_EXECUTION_MODE, OP_FUNCTION, OP_FUNCTION_CALL, OP_FUNCTION_END, OP_MEMBER_NAME, OP_NAME, OP_SOURCE, OP_SOURCE_CONTINUED,
};

const OP_MEMBER_DECORATE: u32 = 72;
const OP_GROUP_DECORATE: u32 = 74;
const OP_GROUP_MEMBER_DECORATE: u32 = 75;
const OP_EXECUTION_MODE_ID: u32 = 331;
const OP_DECORATE_ID: u32 = 332;
const OP_DECORATE_STRING: u32 = 5632;
const OP_MEMBER_DECORATE_STRING: u32 = 5633;

/// Instructions of the debug and annotation sections whose first operand is the id they name or
/// decorate (and execution modes, whose first operand is an entry point's function).
const TARGETED: [u32; 9] = [
    OP_NAME,
    OP_MEMBER_NAME,
    OP_EXECUTION_MODE,
    OP_EXECUTION_MODE_ID,
    OP_DECORATE,
    OP_MEMBER_DECORATE,
    OP_DECORATE_ID,
    OP_DECORATE_STRING,
    OP_MEMBER_DECORATE_STRING,
];

/// A function of the module: its words (OpFunction to OpFunctionEnd), the functions it calls,
/// and the global-section instructions that go with it (its entry point, execution modes, and
/// the names and decorations of the ids it defines).
struct Function {
    words: Range<usize>,
    calls: Vec<u32>,
    owns: Vec<usize>,
}

/// A module indexed once, from which [`EntryPoints::module`] cuts each entry point's module.
pub struct EntryPoints {
    words: Vec<u32>,
    /// The global section's instructions (everything before the first OpFunction).
    globals: Vec<(u32, Range<usize>)>,
    functions: HashMap<u32, Function>,
    /// Function ids in module order.
    order: Vec<u32>,
    /// Global-section instructions not owned by a function (indices into `globals`): kept by a
    /// cut if they define an id the cut refers to, name or decorate one, or define nothing.
    shared: Vec<usize>,
    /// Per global-section instruction: the id it defines (types, constants, variables, ...).
    global_result: Vec<Option<u32>>,
    /// Per global-section instruction: the global id it names or decorates, if it does.
    global_target: Vec<Option<u32>>,
    /// Entry point name -> its function id.
    entries: HashMap<String, u32>,
}

/// Word offset (within its instruction) of the result id of `opcode`, if it has one, from the
/// SPIR-V grammar.
fn result_offset(opcode: u32, cache: &mut HashMap<u32, Option<usize>>) -> Result<Option<usize>, String> {
    if let Some(&o) = cache.get(&opcode) {
        return Ok(o);
    }
    use rspirv::grammar::OperandKind;
    let inst = rspirv::grammar::INSTRUCTION_TABLE
        .lookup_opcode(opcode)
        .ok_or_else(|| format!("SPIR-V opcode {opcode} is not in the grammar"))?;
    let kinds: Vec<&OperandKind> = inst.operands.iter().take(2).map(|o| &o.kind).collect();
    let o = match kinds.as_slice() {
        [OperandKind::IdResultType, OperandKind::IdResult] => Some(2),
        [OperandKind::IdResult, ..] => Some(1),
        _ => None,
    };
    cache.insert(opcode, o);
    Ok(o)
}

impl EntryPoints {
    /// Index `words` (a whole module). Errors on a malformed module or on constructs this cut
    /// does not handle (decoration groups applied with OpGroupDecorate).
    pub fn new(words: Vec<u32>) -> Result<Self, String> {
        let insts = instructions(&words)?;
        let first_function = insts.iter().position(|(op, _)| *op == OP_FUNCTION).unwrap_or(insts.len());
        let mut entries = HashMap::new();
        for (op, r) in &insts[..first_function] {
            match *op {
                OP_ENTRY_POINT if r.len() >= 4 => {
                    entries.insert(spirv_string(&words[r.start + 3..r.end]), words[r.start + 2]);
                }
                OP_GROUP_DECORATE | OP_GROUP_MEMBER_DECORATE => {
                    return Err("SPIR-V module uses OpGroupDecorate, which the per-entry-point cut does not handle".into())
                }
                _ => {}
            }
        }
        let mut cache = HashMap::new();
        let mut functions = HashMap::new();
        let mut order = Vec::new();
        // Which function defines each id defined inside one (0: none; the header's id bound
        // sizes it, and 0 is never an id).
        let bound = words[3] as usize;
        let mut defined_in = vec![0u32; bound];
        let mut i = first_function;
        while i < insts.len() {
            let (op, r) = &insts[i];
            if *op != OP_FUNCTION || r.len() < 3 {
                return Err(format!("SPIR-V: expected OpFunction at word {}, found opcode {op}", r.start));
            }
            let id = words[r.start + 2];
            let start = r.start;
            let mut calls = Vec::new();
            loop {
                let (op, r) = insts.get(i).ok_or_else(|| format!("SPIR-V: function %{id} has no OpFunctionEnd"))?;
                if let Some(o) = result_offset(*op, &mut cache)? {
                    let d = *words.get(r.start + o).filter(|_| o < r.len()).unwrap_or(&0) as usize;
                    *defined_in.get_mut(d).ok_or_else(|| format!("SPIR-V: id %{d} is not below the header's bound {bound}"))? = id;
                }
                if *op == OP_FUNCTION_CALL && r.len() >= 4 {
                    calls.push(words[r.start + 3]);
                }
                i += 1;
                if *op == OP_FUNCTION_END {
                    break;
                }
            }
            order.push(id);
            functions.insert(id, Function { words: start..insts[i - 1].1.end, calls, owns: Vec::new() });
        }
        let mut shared = Vec::new();
        let mut global_result = Vec::with_capacity(first_function);
        let mut global_target = Vec::with_capacity(first_function);
        for (k, (op, r)) in insts[..first_function].iter().enumerate() {
            let target = match *op {
                OP_ENTRY_POINT if r.len() >= 3 => Some(words[r.start + 2]),
                op if TARGETED.contains(&op) && r.len() >= 2 => Some(words[r.start + 1]),
                _ => None,
            };
            let result = match result_offset(*op, &mut cache)? {
                Some(o) if o < r.len() => Some(words[r.start + o]),
                _ => None,
            };
            if result.is_some_and(|d| d as usize >= bound) {
                return Err(format!("SPIR-V: id %{} is not below the header's bound {bound}", result.unwrap_or(0)));
            }
            global_result.push(result);
            match target.and_then(|t| defined_in.get(t as usize)).filter(|&&f| f != 0) {
                Some(f) => {
                    functions.get_mut(f).ok_or_else(|| format!("SPIR-V: %{f} is not a function"))?.owns.push(k);
                    global_target.push(None);
                }
                None => {
                    shared.push(k);
                    global_target.push(target);
                }
            }
        }
        for (name, id) in &entries {
            if !functions.contains_key(id) {
                return Err(format!("SPIR-V: entry point {name:?} names %{id}, which is not a function"));
            }
        }
        for (f, function) in &functions {
            if let Some(c) = function.calls.iter().find(|c| !functions.contains_key(c)) {
                return Err(format!("SPIR-V: %{f} calls %{c}, which is not a function"));
            }
        }
        let mut insts = insts;
        insts.truncate(first_function);
        Ok(EntryPoints { words, globals: insts, functions, order, shared, global_result, global_target, entries })
    }

    /// The entry points' names.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.entries.keys().map(|s| s.as_str())
    }

    /// The module of entry point `name` alone: the header (same id bound), the global section
    /// without the other entry points, without the globals its code does not refer to, and
    /// without names, decorations and execution modes of what is left out, then the functions
    /// it calls, in module order.
    pub fn module(&self, name: &str) -> Result<Vec<u32>, String> {
        let &root = self.entries.get(name).ok_or_else(|| format!("SPIR-V module has no entry point {name:?}"))?;
        let mut kept = HashSet::from([root]);
        let mut stack = vec![root];
        while let Some(f) = stack.pop() {
            for &c in &self.functions[&f].calls {
                if kept.insert(c) {
                    stack.push(c);
                }
            }
        }
        let w = &self.words;
        let bound = w[3] as usize;
        // The ids the cut refers to. Every operand word of a kept instruction counts as a
        // reference: a literal that happens to equal a global's id keeps that global too
        // (harmless), and nothing referred to is ever left out.
        let mut needed = vec![false; bound];
        // Marks the ids among `operands`; true if one was not marked before.
        let mark = |needed: &mut Vec<bool>, operands: &[u32]| {
            let mut grew = false;
            for &x in operands {
                if let Some(n) = needed.get_mut(x as usize) {
                    grew |= !*n;
                    *n = true;
                }
            }
            grew
        };
        for f in &kept {
            let r = self.functions[f].words.clone();
            let mut i = r.start;
            while i < r.end {
                let n = (w[i] >> 16) as usize;
                mark(&mut needed, &w[i + 1..i + n]);
                i += n.max(1);
            }
            for &k in &self.functions[f].owns {
                let r = &self.globals[k].1;
                mark(&mut needed, &w[r.start + 1..r.end]);
            }
        }
        // The source text (OpSource, OpSourceContinued: no semantic impact, and in rust-gpu's
        // output the crate's whole source, 0.2 M words that every cut would carry) is left out.
        let source = |k: usize| matches!(self.globals[k].0, OP_SOURCE | OP_SOURCE_CONTINUED);
        for &k in &self.shared {
            if self.global_result[k].is_none() && self.global_target[k].is_none() && !source(k) {
                let r = &self.globals[k].1;
                mark(&mut needed, &w[r.start + 1..r.end]); // capabilities, memory model, ...
            }
        }
        // Close over the global section: a global refers only to ids defined before it (types
        // before the constants and variables of those types), so one backward pass adds what
        // the needed globals need; the names and decorations of needed ids can refer to ids
        // too (OpDecorateId), hence the loop.
        loop {
            for k in (0..self.globals.len()).rev() {
                if let Some(d) = self.global_result[k] {
                    if needed[d as usize] {
                        let r = &self.globals[k].1;
                        mark(&mut needed, &w[r.start + 1..r.end]);
                    }
                }
            }
            let mut grew = false;
            for &k in &self.shared {
                if self.global_target[k].is_some_and(|t| needed.get(t as usize) == Some(&true)) {
                    let r = &self.globals[k].1;
                    grew |= mark(&mut needed, &w[r.start + 1..r.end]);
                }
            }
            if !grew {
                break;
            }
        }
        let keep_shared = |k: usize| match (self.global_result[k], self.global_target[k]) {
            (Some(d), _) => needed[d as usize],
            (None, Some(t)) => needed.get(t as usize) == Some(&true),
            (None, None) => !source(k),
        };
        // The global section in module order (its layout is ordered: names, then decorations, ...).
        let mut global: Vec<usize> = self.shared.iter().copied().filter(|&k| keep_shared(k)).collect();
        for f in &kept {
            global.extend_from_slice(&self.functions[f].owns);
        }
        global.sort_unstable();
        let mut out = Vec::with_capacity(w.len() / 8);
        out.extend_from_slice(&w[..crate::HEADER_WORDS]);
        for k in global {
            let (op, r) = &self.globals[k];
            // A kept function that is another entry point's (a kernel calling an entry point)
            // stays a plain function: only `name` is an entry point of the cut.
            if *op != OP_ENTRY_POINT || w[r.start + 2] == root {
                out.extend_from_slice(&w[r.clone()]);
            }
        }
        for id in &self.order {
            if kept.contains(id) {
                out.extend_from_slice(&w[self.functions[id].words.clone()]);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inst(op: u32, operands: &[u32]) -> Vec<u32> {
        let mut v = vec![((operands.len() as u32 + 1) << 16) | op];
        v.extend_from_slice(operands);
        v
    }

    fn name(s: &str) -> Vec<u32> {
        let mut b = s.as_bytes().to_vec();
        b.resize((b.len() / 4 + 1) * 4, 0);
        b.chunks(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
    }

    /// Two entry points (%10 "a", %20 "b"); both call %30; "a" also calls %40. %2 void, %3
    /// fn type, %4 float, %5 a float constant used by all, %6 one used by %40 only, %7 an
    /// integer type used by nothing (named and decorated).
    fn module() -> Vec<u32> {
        let mut w = vec![0x0723_0203, 0x0001_0500, 0, 100, 0];
        w.extend(inst(17, &[1])); // OpCapability Shader
        w.extend(inst(14, &[0, 1])); // OpMemoryModel
        w.extend(inst(OP_SOURCE, &[[0, 1].as_slice(), &name("fn a() {}")].concat())); // dropped
        w.extend(inst(OP_ENTRY_POINT, &[[5].as_slice(), &[10], &name("a")].concat()));
        w.extend(inst(OP_ENTRY_POINT, &[[5].as_slice(), &[20], &name("b")].concat()));
        w.extend(inst(OP_EXECUTION_MODE, &[10, 17, 64, 1, 1]));
        w.extend(inst(OP_EXECUTION_MODE, &[20, 17, 64, 1, 1]));
        w.extend(inst(OP_NAME, &[[10].as_slice(), &name("a")].concat()));
        w.extend(inst(OP_NAME, &[[20].as_slice(), &name("b")].concat()));
        w.extend(inst(OP_NAME, &[[40].as_slice(), &name("only_a")].concat()));
        w.extend(inst(OP_DECORATE, &[41, 42])); // NoContraction on a result inside %40
        w.extend(inst(OP_DECORATE, &[21, 42])); // NoContraction on a result inside %20
        w.extend(inst(OP_DECORATE, &[31, 42])); // NoContraction on a result inside %30
        w.extend(inst(OP_NAME, &[[6].as_slice(), &name("two")].concat()));
        w.extend(inst(OP_NAME, &[[7].as_slice(), &name("unused")].concat()));
        w.extend(inst(OP_DECORATE, &[4, 0])); // a decoration on a global id the code uses: kept
        w.extend(inst(OP_DECORATE, &[7, 0])); // one on a global id nothing uses: dropped
        w.extend(inst(19, &[2])); // OpTypeVoid %2
        w.extend(inst(33, &[3, 2])); // OpTypeFunction %3 %2
        w.extend(inst(22, &[4, 32])); // OpTypeFloat %4 32
        w.extend(inst(21, &[7, 32, 0])); // OpTypeInt %7 32 0
        w.extend(inst(43, &[4, 5, 0x3f80_0000])); // OpConstant %4 %5 1.0
        w.extend(inst(43, &[4, 6, 0x4000_0000])); // OpConstant %4 %6 2.0
        for (f, body) in [(30u32, vec![inst(129, &[4, 31, 5, 5])]), (40, vec![inst(129, &[4, 41, 6, 6])])] {
            w.extend(inst(OP_FUNCTION, &[2, f, 0, 3]));
            w.extend(inst(248, &[f + 5])); // OpLabel
            for b in body {
                w.extend(b);
            }
            w.extend(inst(253, &[])); // OpReturn
            w.extend(inst(OP_FUNCTION_END, &[]));
        }
        for (f, calls) in [(10u32, vec![30, 40]), (20, vec![30])] {
            w.extend(inst(OP_FUNCTION, &[2, f, 0, 3]));
            w.extend(inst(248, &[f + 5]));
            for (k, c) in calls.iter().enumerate() {
                w.extend(inst(OP_FUNCTION_CALL, &[2, f + 6 + k as u32, *c]));
            }
            w.extend(inst(129, &[4, f + 1, 5, 5]));
            w.extend(inst(253, &[]));
            w.extend(inst(OP_FUNCTION_END, &[]));
        }
        w
    }

    fn ops(words: &[u32]) -> Vec<(u32, Vec<u32>)> {
        instructions(words).unwrap().into_iter().map(|(op, r)| (op, words[r.start + 1..r.end].to_vec())).collect()
    }

    fn functions(words: &[u32]) -> Vec<u32> {
        ops(words).into_iter().filter(|(op, _)| *op == OP_FUNCTION).map(|(_, o)| o[1]).collect()
    }

    fn decorated(words: &[u32]) -> Vec<u32> {
        ops(words).into_iter().filter(|(op, _)| *op == OP_DECORATE).map(|(_, o)| o[0]).collect()
    }

    #[test]
    fn keeps_what_the_entry_point_calls_and_nothing_else() {
        let e = EntryPoints::new(module()).unwrap();
        let mut names: Vec<&str> = e.names().collect();
        names.sort();
        assert_eq!(names, ["a", "b"]);
        let a = e.module("a").unwrap();
        assert_eq!(functions(&a), [30, 40, 10]);
        assert_eq!(decorated(&a), [41, 31, 4]);
        let b = e.module("b").unwrap();
        assert_eq!(functions(&b), [30, 20]);
        assert_eq!(decorated(&b), [21, 31, 4]);
        let entry_points: Vec<u32> = ops(&b).into_iter().filter(|(op, _)| *op == OP_ENTRY_POINT).map(|(_, o)| o[1]).collect();
        assert_eq!(entry_points, [20]);
        let modes: Vec<u32> = ops(&b).into_iter().filter(|(op, _)| *op == OP_EXECUTION_MODE).map(|(_, o)| o[0]).collect();
        assert_eq!(modes, [20]);
        let named: Vec<u32> = ops(&b).into_iter().filter(|(op, _)| *op == OP_NAME).map(|(_, o)| o[0]).collect();
        assert_eq!(named, [20], "the names of a's functions and constants go with them");
        // Globals: what the kept code refers to (and what those refer to), nothing else.
        let defined = |m: &[u32]| -> Vec<u32> {
            ops(m).into_iter().filter(|(op, _)| [19, 33, 22, 21, 43].contains(op)).map(|(op, o)| if op == 43 { o[1] } else { o[0] }).collect()
        };
        assert_eq!(defined(&a), [2, 3, 4, 5, 6]);
        assert_eq!(defined(&b), [2, 3, 4, 5], "%6 is used by a's %40 only, %7 by nothing");
        let a_named: Vec<u32> = ops(&a).into_iter().filter(|(op, _)| *op == OP_NAME).map(|(_, o)| o[0]).collect();
        assert_eq!(a_named, [10, 40, 6]);
        assert!(ops(&a).iter().all(|(op, _)| *op != OP_SOURCE), "the source text is left out");
        // Header and globals are copied unchanged; kept instructions are word-for-word copies.
        assert_eq!(b[..5], module()[..5]);
        assert!(b.len() < module().len());
    }

    #[test]
    fn unknown_entry_points_and_bad_modules_are_errors() {
        let e = EntryPoints::new(module()).unwrap();
        assert!(e.module("c").unwrap_err().contains("\"c\""));
        assert!(EntryPoints::new(vec![1, 2, 3]).is_err());
        let mut truncated = module();
        truncated.pop(); // drops the last OpFunctionEnd's word count: malformed
        truncated.pop();
        assert!(EntryPoints::new(truncated).is_err());
        let mut grouped = module();
        grouped.splice(5..5, inst(OP_GROUP_DECORATE, &[7, 41]));
        assert!(EntryPoints::new(grouped).err().unwrap().contains("OpGroupDecorate"));
    }
}
