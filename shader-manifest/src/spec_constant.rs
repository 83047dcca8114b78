//! Specialization constants set by rewriting the module: each 32-bit `OpSpecConstant` whose
//! `SpecId` is asked for gets the value as its default literal (SPIR-V 1.6 §2.12). wgpu hands a
//! passthrough SPIR-V module to the driver without a `VkSpecializationInfo`, so this is how the
//! GPU backend specializes a pipeline; the driver then sees the default, which is the value.

use crate::instructions;

const OP_SPEC_CONSTANT_TRUE: u32 = 48;
const OP_SPEC_CONSTANT_FALSE: u32 = 49;
const OP_SPEC_CONSTANT: u32 = 50;
const OP_DECORATE: u32 = 71;
/// The `SpecId` decoration.
const DECORATION_SPEC_ID: u32 = 1;

/// `words` with specialization constant `i` (the one decorated `SpecId i`) set to `values[i]`
/// for every `i < values.len()`, and how many constants were set (0: the module declares none
/// of those ids, and the words are unchanged). Errors on a malformed module and on a `SpecId`
/// asked for that is not a 32-bit `OpSpecConstant` (a boolean or 64-bit one).
pub fn specialize(words: &[u32], values: &[u32]) -> Result<(Vec<u32>, usize), String> {
    let insts = instructions(words)?;
    let bound = words.get(3).copied().unwrap_or(0) as usize;
    // Result id -> the value its SpecId asks for.
    let mut wanted: Vec<Option<u32>> = vec![None; bound];
    for (op, r) in &insts {
        if *op == OP_DECORATE && r.len() == 4 && words[r.start + 2] == DECORATION_SPEC_ID {
            let (target, id) = (words[r.start + 1] as usize, words[r.start + 3] as usize);
            if let Some(&v) = values.get(id) {
                *wanted.get_mut(target).ok_or_else(|| format!("SPIR-V: SpecId {id} decorates %{target}, past the id bound {bound}"))? = Some(v);
            }
        }
    }
    let mut out = words.to_vec();
    let mut set = 0;
    for (op, r) in &insts {
        let result = match *op {
            OP_SPEC_CONSTANT | OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE if r.len() >= 3 => words[r.start + 2] as usize,
            _ => continue,
        };
        let Some(v) = wanted.get(result).copied().flatten() else { continue };
        if *op != OP_SPEC_CONSTANT || r.len() != 4 {
            return Err(format!("SPIR-V: specialization constant %{result} is not a 32-bit OpSpecConstant, so it cannot be set to {v}"));
        }
        out[r.start + 3] = v;
        wanted[result] = None;
        set += 1;
    }
    if let Some(t) = wanted.iter().position(|w| w.is_some()) {
        return Err(format!("SPIR-V: %{t} is decorated with a SpecId but is not a specialization constant"));
    }
    Ok((out, set))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A module of `insts` (each instruction's words after the opcode word) behind a header
    /// with id bound 16.
    fn module(insts: &[(u32, &[u32])]) -> Vec<u32> {
        let mut w = vec![0x0723_0203, 0x0001_0000, 0, 16, 0];
        for (op, operands) in insts {
            w.push(((operands.len() as u32 + 1) << 16) | op);
            w.extend_from_slice(operands);
        }
        w
    }

    #[test]
    fn sets_the_asked_ids_and_nothing_else() {
        // %3 = SpecId 0 (default 7), %4 = SpecId 1 (default 9), %5 = SpecId 2 (default 11).
        let m = module(&[
            (OP_DECORATE, &[3, DECORATION_SPEC_ID, 0]),
            (OP_DECORATE, &[4, DECORATION_SPEC_ID, 1]),
            (OP_DECORATE, &[5, DECORATION_SPEC_ID, 2]),
            (OP_SPEC_CONSTANT, &[2, 3, 7]),
            (OP_SPEC_CONSTANT, &[2, 4, 9]),
            (OP_SPEC_CONSTANT, &[2, 5, 11]),
        ]);
        let (s, n) = specialize(&m, &[70, 90]).unwrap();
        assert_eq!(n, 2);
        // The three OpSpecConstants are the last 12 words, their literals each one's fourth word.
        let defaults: Vec<u32> = (0..3).map(|k| s[m.len() - 12 + 4 * k + 3]).collect();
        assert_eq!(defaults, vec![70, 90, 11]);
        // Only those two words differ.
        assert_eq!(s.iter().zip(&m).filter(|(a, b)| a != b).count(), 2);
        // No values, or ids the module lacks: unchanged.
        assert_eq!(specialize(&m, &[]).unwrap(), (m.clone(), 0));
        let other = module(&[(OP_SPEC_CONSTANT, &[2, 3, 7])]);
        assert_eq!(specialize(&other, &[1, 2, 3]).unwrap(), (other.clone(), 0));
    }

    #[test]
    fn refuses_what_it_cannot_set() {
        let boolean = module(&[(OP_DECORATE, &[3, DECORATION_SPEC_ID, 0]), (OP_SPEC_CONSTANT_TRUE, &[2, 3])]);
        assert!(specialize(&boolean, &[0]).unwrap_err().contains("not a 32-bit OpSpecConstant"));
        let wide = module(&[(OP_DECORATE, &[3, DECORATION_SPEC_ID, 0]), (OP_SPEC_CONSTANT, &[2, 3, 1, 0])]);
        assert!(specialize(&wide, &[5]).unwrap_err().contains("not a 32-bit OpSpecConstant"));
        let not_constant = module(&[(OP_DECORATE, &[3, DECORATION_SPEC_ID, 0])]);
        assert!(specialize(&not_constant, &[5]).unwrap_err().contains("not a specialization constant"));
        assert!(specialize(&[1, 2, 3], &[5]).unwrap_err().contains("not a SPIR-V module"));
    }
}
