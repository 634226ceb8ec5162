//! Contour lines of a value on a 2-D grid (marching squares, linear
//! interpolation on cell edges) and the fit of the paper's eq. (61),
//! B̄3 = Ω B̄1^(−ι), to contours of R* (Sec. 4.2: ι ≈ 0.9).

/// A value on a rectilinear grid: `z[i * y.len() + j]` at `(x[i], y[j])`;
/// NaN where unknown.
#[derive(Debug, Clone, Copy)]
pub struct GridField<'a> {
    /// First axis.
    pub x: &'a [f64],
    /// Second axis.
    pub y: &'a [f64],
    /// Values, row-major.
    pub z: &'a [f64],
}

/// A contour segment between two points (x, y).
pub type Segment = [(f64, f64); 2];

impl GridField<'_> {
    fn at(&self, i: usize, j: usize) -> f64 {
        self.z[i * self.y.len() + j]
    }

    /// The segments of the contour z = level (cells with a NaN corner are
    /// skipped; a saddle cell pairs its crossings in edge order).
    pub fn contour(&self, level: f64) -> Vec<Segment> {
        let mut out = vec![];
        for i in 0..self.x.len().saturating_sub(1) {
            for j in 0..self.y.len().saturating_sub(1) {
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let values = corners.map(|(a, b)| self.at(a, b));
                if values.iter().any(|v| v.is_nan()) {
                    continue;
                }
                let crossings: Vec<(f64, f64)> = (0..4)
                    .filter_map(|e| {
                        let (p, q) = (e, (e + 1) % 4);
                        let (va, vb) = (values[p] - level, values[q] - level);
                        if (va < 0.0) == (vb < 0.0) {
                            return None;
                        }
                        let t = va / (va - vb);
                        let (pa, pb) = (corners[p], corners[q]);
                        Some((
                            self.x[pa.0] + t * (self.x[pb.0] - self.x[pa.0]),
                            self.y[pa.1] + t * (self.y[pb.1] - self.y[pa.1]),
                        ))
                    })
                    .collect();
                out.extend(crossings.chunks_exact(2).map(|c| [c[0], c[1]]));
            }
        }
        out
    }

    /// Finite minimum and maximum of z.
    pub fn range(&self) -> Option<(f64, f64)> {
        let finite = self.z.iter().copied().filter(|v| v.is_finite());
        let lo = finite.clone().fold(f64::INFINITY, f64::min);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max);
        (lo < hi).then_some((lo, hi))
    }

    /// `count` levels evenly inside the range (the ends excluded).
    pub fn levels(&self, count: usize) -> Vec<f64> {
        self.range().map_or(vec![], |(lo, hi)| {
            (1..=count)
                .map(|k| lo + (hi - lo) * k as f64 / (count + 1) as f64)
                .collect()
        })
    }
}

/// The fit of B̄3 = Ω B̄1^(−ι) (paper (61)) to several contours at once:
/// one common exponent, one Ω per contour.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerFit {
    /// ι, the common exponent.
    pub iota: f64,
    /// Each contour used: its level, Ω (with the common ι), the number of
    /// points, and the contour's own exponent (its separate slope).
    pub contours: Vec<ContourFit>,
    /// Root-mean-square residual of ln B̄3.
    pub rms: f64,
}

/// One contour of a [`PowerFit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContourFit {
    /// The value on the contour.
    pub level: f64,
    /// Ω with the common exponent.
    pub omega: f64,
    /// Contour points used.
    pub points: usize,
    /// The exponent of this contour alone.
    pub iota: f64,
}

/// Least-squares slope of v on u, and the means.
fn slope(p: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = p.len() as f64;
    let mx = p.iter().map(|q| q.0).sum::<f64>() / n;
    let my = p.iter().map(|q| q.1).sum::<f64>() / n;
    let sxy: f64 = p.iter().map(|(u, v)| (u - mx) * (v - my)).sum();
    let sxx: f64 = p.iter().map(|(u, _)| (u - mx).powi(2)).sum();
    (sxy / sxx, mx, my)
}

/// Fits ln y = ln Ω_l − ι ln x by least squares with a common slope over
/// the contour points (segment midpoints) of `levels`; contours with fewer
/// than 3 points are left out. None without two usable points.
pub fn fit_power_law(field: &GridField, levels: &[f64]) -> Option<PowerFit> {
    let groups: Vec<(f64, Vec<(f64, f64)>)> = levels
        .iter()
        .map(|&l| {
            let pts = field
                .contour(l)
                .iter()
                .map(|[a, b]| ((0.5 * (a.0 + b.0)).ln(), (0.5 * (a.1 + b.1)).ln()))
                .filter(|(u, v)| u.is_finite() && v.is_finite())
                .collect();
            (l, pts)
        })
        .filter(|(_, p): &(f64, Vec<(f64, f64)>)| p.len() >= 3)
        .collect();
    let mean = |p: &[(f64, f64)]| {
        let n = p.len() as f64;
        (
            p.iter().map(|q| q.0).sum::<f64>() / n,
            p.iter().map(|q| q.1).sum::<f64>() / n,
        )
    };
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (_, p) in &groups {
        let (mx, my) = mean(p);
        for (u, v) in p {
            sxy += (u - mx) * (v - my);
            sxx += (u - mx).powi(2);
        }
    }
    if groups.is_empty() || sxx <= 0.0 {
        return None;
    }
    let iota = -sxy / sxx;
    let (mut sse, mut count) = (0.0, 0usize);
    let contours = groups
        .iter()
        .map(|(l, p)| {
            let (mx, my) = mean(p);
            let ln_omega = my + iota * mx;
            for (u, v) in p {
                sse += (v - (ln_omega - iota * u)).powi(2);
                count += 1;
            }
            ContourFit {
                level: *l,
                omega: ln_omega.exp(),
                points: p.len(),
                iota: -slope(p).0,
            }
        })
        .collect();
    Some(PowerFit {
        iota,
        contours,
        rms: (sse / count as f64).sqrt(),
    })
}
