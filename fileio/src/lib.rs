//! Files the feature crates read and write: multi-channel float EXR images ([`write_exr`],
//! [`read_exr`]) and outputs written atomically ([`write_atomic`], [`write_file`]) or as a set
//! that appears all at once ([`FileSet`]).
//!
//! ```
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("ramp.exr");
//! fileio::write_exr(&path, 2, 1, &[("Y", &[0.25, 0.5])])?;
//! let img = fileio::read_exr(&path)?;
//! assert_eq!((img.width, img.height), (2, 1));
//! assert_eq!(img.channel("Y")?, &[0.25, 0.5]);
//! assert!(img.channel("R").is_err());
//! # Ok::<(), anyhow::Error>(())
//! ```

use anyhow::{anyhow, bail, Context, Result};
use exr::prelude::*;
use std::path::Path;

/// Write one layer of named f32 channels (each `width * height`, row-major, top row first).
pub fn write_exr(path: &Path, width: usize, height: usize, channels: &[(&str, &[f32])]) -> Result<()> {
    let mut list = smallvec::SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    for (name, data) in channels {
        if data.len() != width * height {
            bail!("channel {name} has {} values, expected {width}x{height}", data.len());
        }
        list.push(AnyChannel::new(*name, FlatSamples::F32(data.to_vec())));
    }
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        // Chunks in increasing order (the default lets the writer emit them as they finish), so
        // equal images give byte-identical files.
        Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS },
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    write_atomic(path, |tmp| image.write().to_file(tmp).map_err(anyhow::Error::from))
}

/// Create the directory a file is about to be written to.
pub fn create_parent_dir(path: &Path) -> Result<()> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            std::fs::create_dir_all(dir).with_context(|| format!("creating directory {}", dir.display()))
        }
        _ => Ok(()),
    }
}

/// Check, before any work, that output file `path` can be written: create its directory and
/// create and remove a probe file there. Every command that writes files calls this first, so
/// a read-only or missing location fails at once, naming the directory and the file.
pub fn prepare_output(path: &Path) -> Result<()> {
    create_parent_dir(path).with_context(|| format!("cannot write {}", path.display()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let probe = dir.join(format!(".host-write-probe-{}", std::process::id()));
    std::fs::File::create(&probe)
        .and_then(|_| std::fs::remove_file(&probe))
        .with_context(|| format!("cannot write {}: directory {} is not writable", path.display(), dir.display()))
}

/// [`prepare_output`] for a file the command will create: also refuses a `path` that is an
/// existing directory (or ends in a separator), which a write would fail on only at the end.
pub fn check_output_file(path: &Path) -> Result<()> {
    let s = path.as_os_str().to_string_lossy();
    if path.is_dir() || s.ends_with('/') || s.ends_with(std::path::MAIN_SEPARATOR) {
        bail!("cannot write {}: it is a directory; give a file name (such as {})", path.display(), path.join("render.exr").display());
    }
    if path.file_name().is_none() {
        bail!("cannot write {}: not a file name", path.display());
    }
    prepare_output(path)
}

/// The temporary name [`write_atomic`] and [`FileSet`] write `path` under: `.tmp-<pid>-<name>`
/// in the same directory (so the rename stays on one file system, and an extension-sniffing
/// encoder sees the same extension).
pub fn temp_name(path: &Path) -> Result<std::path::PathBuf> {
    let name = path.file_name().with_context(|| format!("{} is not a file name", path.display()))?;
    Ok(path.with_file_name(format!(".tmp-{}-{}", std::process::id(), name.to_string_lossy())))
}

/// The files of one result written as a set: each is written to its temporary name
/// ([`temp_name`]) by [`stage`](Self::stage), and [`commit`](Self::commit) renames them all to
/// their names only when every one was written. A set dropped without a commit (a write failed,
/// or the command gave up) removes its temporaries, so an earlier result's files stay as they
/// were, all of them, rather than a new image beside an old summary.
#[derive(Debug, Default)]
pub struct FileSet {
    /// (temporary, final) of every staged file.
    staged: Vec<(std::path::PathBuf, std::path::PathBuf)>,
}

impl FileSet {
    /// An empty set.
    pub fn new() -> FileSet {
        FileSet::default()
    }

    /// Stage `paths` (one or more files that one writer produces together): `write` is given
    /// the temporary name of the first and must create the temporary names of all of them
    /// (a writer that derives a second file from the first's name, `x.exr` -> `x.json`,
    /// derives `.tmp-<pid>-x.json`). Errors name the file.
    pub fn stage(&mut self, paths: &[&Path], write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let mut temps = Vec::with_capacity(paths.len());
        for p in paths {
            let t = temp_name(p)?;
            if self.staged.iter().any(|(_, f)| f == p) {
                bail!("{} is written twice in one set of outputs", p.display());
            }
            self.staged.push((t.clone(), p.to_path_buf()));
            temps.push(t);
        }
        let first = paths.first().with_context(|| "staging no file".to_string())?;
        create_parent_dir(first)?;
        write(&temps[0]).with_context(|| format!("writing {}", first.display()))?;
        for (t, p) in temps.iter().zip(paths) {
            if !t.is_file() {
                bail!("writing {}: the writer did not create it", p.display());
            }
        }
        Ok(())
    }

    /// Rename every staged file to its name. Returns the names, in staging order.
    pub fn commit(mut self) -> Result<Vec<std::path::PathBuf>> {
        let staged = std::mem::take(&mut self.staged);
        for (i, (t, p)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(t, p) {
                for (t, _) in &staged[i..] {
                    let _ = std::fs::remove_file(t);
                }
                return Err(anyhow!(e)).with_context(|| format!("renaming {} to {}", t.display(), p.display()));
            }
        }
        Ok(staged.into_iter().map(|(_, p)| p).collect())
    }
}

impl Drop for FileSet {
    fn drop(&mut self) {
        for (t, _) in &self.staged {
            let _ = std::fs::remove_file(t);
        }
    }
}

/// Write `path` through `write`, which writes a temporary file in the same directory (its name
/// ends in `path`'s own name, so an extension-sniffing encoder sees the same extension); the
/// temporary file then replaces `path` by a rename. A failed write leaves an existing `path`
/// untouched and removes the temporary file. Errors name `path`.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    create_parent_dir(path)?;
    let tmp = temp_name(path)?;
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(anyhow::Error::from));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("writing {}", path.display()))
}

/// Write a text (or any byte) file atomically ([`write_atomic`]).
pub fn write_file(path: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    write_atomic(path, |tmp| std::fs::write(tmp, contents.as_ref()).map_err(anyhow::Error::from))
}


/// A float image read from an EXR file: its size and named channels.
#[derive(Debug, Clone)]
pub struct ExrImage {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrImage {
    /// The channel called `name`; the error lists the channels present.
    pub fn channel(&self, name: &str) -> Result<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, d)| d.as_slice())
            .ok_or_else(|| {
                let have: Vec<&str> = self.channels.iter().map(|(n, _)| n.as_str()).collect();
                anyhow!("EXR has no channel {name:?} (channels: {})", have.join(", "))
            })
    }
}

/// Read the first layer of an EXR file, every channel converted to f32.
pub fn read_exr(path: &Path) -> Result<ExrImage> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("reading EXR {}", path.display()))?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let channels = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let data: Vec<f32> = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), data)
        })
        .collect();
    Ok(ExrImage { width, height, channels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("fileio_test_{}", std::process::id()));
        let path = dir.join("a.png");
        write_file(&path, "old").unwrap();
        let e = write_atomic(&path, |tmp| {
            std::fs::write(tmp, "half")?;
            anyhow::bail!("encoder failed")
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains(&path.display().to_string()), "{e:#}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        write_file(&path, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        prepare_output(&dir.join("sub/b.exr")).unwrap();
        assert!(format!("{:#}", check_output_file(&dir).unwrap_err()).contains("is a directory"));
        assert!(prepare_output(&path.join("c.exr")).is_err());
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_file_set_renames_all_or_nothing() {
        let dir = tempfile_dir("set");
        let (a, b, c) = (dir.join("r.exr"), dir.join("r.png"), dir.join("r.json"));
        for p in [&a, &b, &c] {
            write_file(p, "old").unwrap();
        }
        // the third write fails: the first two stay at their old contents, no temporaries
        let mut set = FileSet::new();
        set.stage(&[&a], |t| Ok(std::fs::write(t, "new")?)).unwrap();
        set.stage(&[&b], |t| Ok(std::fs::write(t, "new")?)).unwrap();
        assert!(set.stage(&[&c], |_| anyhow::bail!("disk full")).is_err());
        drop(set);
        for p in [&a, &b, &c] {
            assert_eq!(std::fs::read_to_string(p).unwrap(), "old", "{}", p.display());
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3, "a temporary was left");
        // all written: all renamed; a writer of two files at once
        let mut set = FileSet::new();
        set.stage(&[&a, &c], |t| {
            std::fs::write(t, "new")?;
            Ok(std::fs::write(t.with_extension("json"), "new")?)
        })
        .unwrap();
        set.stage(&[&b], |t| Ok(std::fs::write(t, "new")?)).unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old", "renamed before the commit");
        set.commit().unwrap();
        for p in [&a, &b, &c] {
            assert_eq!(std::fs::read_to_string(p).unwrap(), "new", "{}", p.display());
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
        let _ = std::fs::remove_dir_all(dir);
    }

    fn tempfile_dir(what: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("fileio_{what}_{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }
}
