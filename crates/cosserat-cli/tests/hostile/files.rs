//! Result files made inconsistent or damaged: named errors, never a
//! panic or a crash in the HDF5 library.

use super::*;
use cosserat::output::store::Values;

/// Replaces dataset `name` of the HDF5 file at `path` by `data` (shape
/// `[data.len()]`), keeping its type family. The seal is taken off first:
/// the file stands for one written by another program, which is read
/// unverified, so the dataset checks themselves are what is tested.
pub(crate) fn replace_dataset<T: Column>(path: &Path, name: &str, data: &[T]) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        &bytes[bytes.len() - 24..bytes.len() - 8],
        b"cosserat-seal-v1"
    );
    std::fs::write(path, &bytes[..bytes.len() - 24]).unwrap();
    common::h5::rewrite(path, |f| {
        assert!(f.remove(name), "{name}");
        f.put(name, &[data.len()], T::values(data)).unwrap();
    });
}

/// The element types a damaged dataset is written with.
pub(crate) trait Column: Copy {
    fn values(data: &[Self]) -> Values;
}

impl Column for f64 {
    fn values(data: &[Self]) -> Values {
        Values::Floats(data.to_vec())
    }
}

impl Column for u64 {
    fn values(data: &[Self]) -> Values {
        Values::Counts(data.to_vec())
    }
}

/// Files whose datasets contradict each other (a special point on a branch
/// that does not exist, 3-vectors of length 4, a point index outside the
/// grid, a column with too few rows) are named errors of `plot`, `merge`
/// and `--resume`, never a panic or a silently truncated result.
#[test]
fn inconsistent_result_files_are_named_errors() {
    type Damage = Box<dyn Fn(&Path)>;
    let dir = common::run::scratch("hostile", "files");
    let fx = fixtures(&dir);
    let cases: Vec<(&str, Damage, Vec<&str>)> = vec![
        (
            "d.h5",
            Box::new(|p: &Path| replace_dataset(p, "special_points/branch", &[99u64, 99])),
            vec!["plot", "d.h5", "-o", "f.png"],
        ),
        (
            "d.h5",
            Box::new(|p: &Path| {
                replace_dataset(p, "branches/0/tip_position", &[1.0f64, 2.0, 3.0, 4.0]);
            }),
            vec!["plot", "d.h5", "-o", "f.png"],
        ),
        (
            "d.h5",
            Box::new(|p: &Path| replace_dataset(p, "branches/0/parameter", &[f64::NAN])),
            vec!["plot", "d.h5", "-o", "f.png"],
        ),
        (
            "d.h5",
            Box::new(|p: &Path| replace_dataset(p, "branches/0/stable", &[1u64])),
            vec!["export", "d.h5", "--format", "vtk"],
        ),
        (
            "d.h5",
            Box::new(|p: &Path| replace_dataset(p, "branches/0/shapes", &[1.0f64, 2.0, 3.0, 4.0])),
            vec!["export", "d.h5", "--format", "xdmf"],
        ),
        (
            "d.h5",
            Box::new(|p: &Path| replace_dataset(p, "branches/0/parameter", &[f64::NAN])),
            vec!["export", "d.h5", "--format", "vtk"],
        ),
        (
            "s.h5",
            Box::new(|p: &Path| replace_dataset(p, "points/index", &[1_000_000u64, 1])),
            vec!["merge", "s.h5", "-o", "m.h5"],
        ),
        (
            "s.h5",
            Box::new(|p: &Path| replace_dataset(p, "points/index", &[0u64, 0])),
            vec!["merge", "s.h5", "-o", "m.h5"],
        ),
    ];
    for (k, (file, damage, args)) in cases.iter().enumerate() {
        let case_dir = dir.join(format!("case{k}"));
        std::fs::create_dir_all(&case_dir).unwrap();
        let bytes = if *file == "d.h5" {
            &fx.diagram
        } else {
            &fx.shards[0]
        };
        std::fs::write(case_dir.join(file), bytes).unwrap();
        damage(&case_dir.join(file));
        let o = Command::new(BIN)
            .args(args)
            .current_dir(&case_dir)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {k} {args:?}: {err}");
        assert!(
            err.contains("error:") && err.contains(file),
            "case {k}: {err}"
        );
        let left: Vec<_> = std::fs::read_dir(&case_dir).unwrap().collect();
        assert_eq!(left.len(), 1, "case {k}: nothing written");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A sealed result file with one byte changed is refused by its checksum
/// before the HDF5 library reads it (damaged files crashed it: SIGSEGV in
/// `merge`, an impossible allocation in `plot`).
#[test]
fn damaged_sealed_files_are_refused_before_hdf5_reads_them() {
    let dir = common::run::scratch("hostile", "seal");
    let fx = fixtures(&dir);
    for (k, (bytes, args)) in [
        (&fx.diagram, vec!["plot", "x.h5", "-o", "f.png"]),
        (&fx.shards[0], vec!["merge", "x.h5", "-o", "m.h5"]),
        (&fx.diagram, vec!["export", "x.h5", "--format", "xdmf"]),
    ]
    .into_iter()
    .enumerate()
    {
        // Damage in the data, and in the data and the seal's magic together
        // (damage to the magic alone leaves the data intact and readable).
        let n = bytes.len();
        for at in [vec![100], vec![n / 2], vec![n - 30], vec![n - 20, 100]] {
            let case_dir = dir.join(format!("case{k}-{}", at[0]));
            std::fs::create_dir_all(&case_dir).unwrap();
            let mut b = bytes.clone();
            for &i in &at {
                b[i] ^= 0x5a;
            }
            std::fs::write(case_dir.join("x.h5"), &b).unwrap();
            let o = Command::new(BIN)
                .args(&args)
                .current_dir(&case_dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?} at {at:?}: {err}");
            assert!(err.contains("damaged"), "{err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
