//! The collocation mesh 0 = s_0 < … < s_N = L and its adaptation.
//!
//! A cold start uses N equal intervals; a warm start reuses the previous
//! mesh stretched to the new length. The mesh is refined by splitting an
//! interval i into q equal pieces; the solver picks q from the interval's
//! local error estimate e_i and its share tol · h_i / L of the tolerance,
//! with q^{2m} ≥ e_i / share since the local error is O(h^{2m+1}).

pub(super) fn uniform_mesh(length: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| {
            if i == n {
                length
            } else {
                length * i as f64 / n as f64
            }
        })
        .collect()
}

/// A mesh stretched to end exactly at `length`.
pub(super) fn rescale_mesh(mesh: &[f64], length: f64) -> Vec<f64> {
    let end = *mesh.last().unwrap();
    let mut m: Vec<f64> = mesh.iter().map(|s| s * length / end).collect();
    *m.last_mut().unwrap() = length;
    m
}

/// The mesh with a node at each of `points` (sorted, inside (s_0, s_N)):
/// the collocation equations hold on each side of a jump of the
/// right-hand side (a point force), never across it, so the jump costs no
/// order. A node already within 1e-12 of the interval's width of a point
/// is moved onto it rather than doubled; refinement keeps every node, so
/// the points stay nodes.
pub(super) fn with_nodes_at(mesh: Vec<f64>, points: &[f64]) -> Vec<f64> {
    if points.is_empty() {
        return mesh;
    }
    let mut out = mesh;
    for &p in points {
        let i = out.partition_point(|&s| s < p);
        if i == 0 || i == out.len() {
            continue;
        }
        let width = out[i] - out[i - 1];
        if (out[i] - p).abs() <= 1e-12 * width {
            out[i] = p;
        } else if (p - out[i - 1]).abs() <= 1e-12 * width && i > 1 {
            out[i - 1] = p;
        } else {
            out.insert(i, p);
        }
    }
    out
}

/// The mesh with the `flagged` intervals (sorted indices) halved.
#[cfg(test)]
fn refine(mesh: &[f64], flagged: &[usize]) -> Vec<f64> {
    let pieces: Vec<(usize, usize)> = flagged.iter().map(|&i| (i, 2)).collect();
    refine_into(mesh, &pieces)
}

/// The mesh with interval i split into q equal pieces for every (i, q) of
/// `pieces` (sorted by i).
pub(super) fn refine_into(mesh: &[f64], pieces: &[(usize, usize)]) -> Vec<f64> {
    let mut out = Vec::with_capacity(mesh.len() + pieces.iter().map(|p| p.1).sum::<usize>());
    let mut f = pieces.iter().peekable();
    for i in 0..mesh.len() - 1 {
        out.push(mesh[i]);
        if let Some(&&(_, q)) = f.peek().filter(|p| p.0 == i) {
            f.next();
            let h = mesh[i + 1] - mesh[i];
            out.extend((1..q).map(|j| mesh[i] + h * j as f64 / q as f64));
        }
    }
    out.push(*mesh.last().unwrap());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jump_becomes_a_node() {
        assert_eq!(
            with_nodes_at(vec![0.0, 1.0, 2.0], &[0.5]),
            vec![0.0, 0.5, 1.0, 2.0]
        );
        assert_eq!(
            with_nodes_at(vec![0.0, 1.0, 2.0], &[1.0]),
            vec![0.0, 1.0, 2.0]
        );
    }

    #[test]
    fn refine_halves_flagged_intervals() {
        assert_eq!(refine(&[0.0, 1.0, 2.0], &[1]), vec![0.0, 1.0, 1.5, 2.0]);
    }
}
