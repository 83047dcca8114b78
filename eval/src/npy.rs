//! NumPy `.npy` arrays (format versions 1.0 to 3.0): read little-endian f32 / f64 arrays of any
//! rank in C or Fortran order, write C-order f32. The format is NumPy's NEP 1.

use anyhow::{anyhow, bail, Result};
use std::io::Write;

/// An array read from a `.npy` file: its shape and its values in C (row-major) order as f32.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub values: Vec<f32>,
}

const MAGIC: &[u8] = b"\x93NUMPY";

/// The value of `key` in the header dictionary (the text after `'key':` up to the next
/// top-level comma or closing brace).
fn header_field<'a>(header: &'a str, key: &str) -> Result<&'a str> {
    let k = format!("'{key}'");
    let at = header.find(&k).ok_or_else(|| anyhow!("the .npy header has no {k} entry: {header:?}"))?;
    let rest = header[at + k.len()..].trim_start();
    let rest = rest.strip_prefix(':').ok_or_else(|| anyhow!("malformed .npy header near {k}: {header:?}"))?.trim_start();
    let mut depth = 0;
    for (i, c) in rest.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' | '}' if depth == 0 => return Ok(rest[..i].trim()),
            _ => {}
        }
    }
    bail!("malformed .npy header: {header:?}")
}

/// Parse a `.npy` file. Accepted dtypes: `<f4` and `<f8` (f64 values are rounded to the
/// nearest f32, as `as f32` does); anything else is an error naming the dtype.
pub fn read(bytes: &[u8]) -> Result<NpyArray> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        bail!("not a NumPy .npy file (missing the \\x93NUMPY magic)");
    }
    let major = bytes[6];
    let (header_len, start) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => {
            if bytes.len() < 12 {
                bail!("truncated .npy header");
            }
            (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12)
        }
        v => bail!(".npy format version {v} is not supported (1, 2 and 3 are)"),
    };
    let header = bytes.get(start..start + header_len).ok_or_else(|| anyhow!("truncated .npy header"))?;
    let header = std::str::from_utf8(header).map_err(|_| anyhow!("the .npy header is not text"))?;
    let descr = header_field(header, "descr")?.trim_matches(|c| c == '\'' || c == '"');
    let fortran = match header_field(header, "fortran_order")? {
        "False" => false,
        "True" => true,
        v => bail!("malformed .npy header: fortran_order = {v}"),
    };
    let shape_text = header_field(header, "shape")?;
    let inner = shape_text
        .strip_prefix('(')
        .and_then(|s| s.strip_suffix(')'))
        .ok_or_else(|| anyhow!("malformed .npy shape {shape_text}"))?;
    let shape: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| anyhow!("malformed .npy shape {shape_text}")))
        .collect::<Result<_>>()?;
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or_else(|| anyhow!("the .npy shape {shape:?} is too large"))?;
    let width = match descr {
        "<f4" => 4,
        "<f8" => 8,
        d => bail!("the .npy dtype is {d:?}; expected little-endian float32 ('<f4') or float64 ('<f8')"),
    };
    let data = &bytes[start + header_len..];
    if data.len() != count * width {
        bail!("the .npy data holds {} bytes; shape {shape:?} of {descr} needs {}", data.len(), count * width);
    }
    let flat: Vec<f32> = if width == 4 {
        data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
    } else {
        data.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")) as f32).collect()
    };
    let values = if fortran && shape.len() == 2 {
        let (r, c) = (shape[0], shape[1]);
        let mut v = vec![0.0f32; count];
        for j in 0..c {
            for i in 0..r {
                v[i * c + j] = flat[j * r + i];
            }
        }
        v
    } else if fortran && shape.len() > 2 {
        bail!("Fortran-order .npy arrays of rank {} are not supported (save with numpy.ascontiguousarray)", shape.len());
    } else {
        flat
    };
    Ok(NpyArray { shape, values })
}

/// Write a C-order little-endian f32 array (format 1.0, header padded to 64 bytes).
pub fn write(w: &mut impl Write, shape: &[usize], values: &[f32]) -> Result<()> {
    let count: usize = shape.iter().product();
    if count != values.len() {
        bail!("shape {shape:?} needs {count} values, got {}", values.len());
    }
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_text = if dims.len() == 1 { format!("({},)", dims[0]) } else { format!("({})", dims.join(", ")) };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape_text}, }}");
    let unpadded = MAGIC.len() + 4 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    w.write_all(MAGIC)?;
    w.write_all(&[1, 0])?;
    w.write_all(&(header.len() as u16).to_le_bytes())?;
    w.write_all(header.as_bytes())?;
    let mut data = Vec::with_capacity(values.len() * 4);
    for v in values {
        data.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&data)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_bits_and_shape() {
        let v = [1.0f32, -0.0, f32::from_bits(1), 3.5, f32::MAX, 0.1];
        let mut b = Vec::new();
        write(&mut b, &[3, 2], &v).unwrap();
        assert_eq!((MAGIC.len() + 4 + u16::from_le_bytes([b[8], b[9]]) as usize) % 64, 0);
        let a = read(&b).unwrap();
        assert_eq!(a.shape, vec![3, 2]);
        assert_eq!(a.values.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), v.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
    }

    /// A file as numpy 1.26 writes `np.array([[1., 2.], [3., 4.]], dtype='<f8', order='F')`.
    #[test]
    fn reads_fortran_order_f64() {
        let mut header = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 2), }".to_string();
        let unpadded = 10 + header.len() + 1;
        header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
        header.push('\n');
        let mut b = MAGIC.to_vec();
        b.extend_from_slice(&[1, 0]);
        b.extend_from_slice(&(header.len() as u16).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        for x in [1.0f64, 3.0, 2.0, 4.0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        let a = read(&b).unwrap();
        assert_eq!(a.values, vec![1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn bad_files_are_named() {
        assert!(read(b"hello world").unwrap_err().to_string().contains("magic"));
        let mut b = Vec::new();
        write(&mut b, &[2], &[1.0, 2.0]).unwrap();
        let mut ints = b.clone();
        let at = ints.windows(3).position(|w| w == b"<f4").unwrap();
        ints[at + 1] = b'i';
        assert!(read(&ints).unwrap_err().to_string().contains("'<f4'"));
        b.pop();
        assert!(read(&b).unwrap_err().to_string().contains("needs 8"));
    }
}
