//! What every dataset of a result file means: its `units` and
//! `description` attributes, attached to every dataset of a file as it is
//! written, and the file's `schema_version` (docs/hdf5-schema.md lists the
//! paths). Units are those of the problem file (its documented units: m,
//! N, N·m); "1" is dimensionless, "" marks text and indices. A dataset
//! this table does not know gets the description "undescribed" — the
//! tests read every file the commands write and refuse any such dataset.

use super::store::Group;

/// The version of the layout described by docs/hdf5-schema.md.
pub const SCHEMA_VERSION: &str = "2";

/// The description given to a dataset the table does not know.
pub const UNDESCRIBED: &str = "undescribed";

/// (units, description) of the dataset `name` in the group `parent` (its
/// last path component, "" for the root).
fn entry(parent: &str, name: &str) -> (&'static str, &'static str) {
    if let Some(e) = (parent == "curve").then(|| curve_entry(name)).flatten() {
        return e;
    }
    match (parent, name) {
        // Equilibria (solve, stability).
        ("solution", "s") => ("m", "arc length of each sample"),
        ("solution", "position") => ("m", "centreline r(s), global components"),
        ("solution", "d1" | "d2" | "d3") => ("1", "director d_i(s), global components"),
        ("solution", "curvature") => ("1/m", "curvature-twist κ(s), body components"),
        ("solution", "moment") => ("N·m", "internal moment M(s), body components"),
        ("solution", "force") => ("N", "internal force n(s), global components"),
        ("solution", "residual_history") => ("1", "scaled Newton residual per iteration"),
        ("solution", "unknowns") => ("", "the discrete unknowns of the shooting discretization (κ(0), reactions, segment states)"),
        (_, "nodes") => ("m", "arc length of the finite-element nodes"),
        (_, "eigenvalues") => ("N·m (stiffness units of the pencil)", "lowest eigenvalues of the second variation (per row a point, or per block)"),
        (_, "eigenvectors") => ("1", "eigenvectors at the nodes (three fields per node)"),
        (_, "null_vector") => ("1", "the mode at the critical load, at the nodes"),
        (_, "null_vectors") => ("1", "null modes of the special points at the nodes"),
        (_, "morse_index") => ("", "number of negative eigenvalues of the second variation"),
        (_, "critical_load") => ("1", "critical load factor of the fixed shape"),
        (_, "load_factor") => ("1", "the critical load as a factor of the problem's loads"),
        // Diagrams.
        ("branches", "eigenvalue_names") => ("", "the tracked block of each eigenvalue column"),
        ("branches", "measure_names") => ("", "the user's measure of each measure column"),
        (_, "parameter") => ("as the continued key", "value of the continuation parameter"),
        (_, "tip_position") => ("m", "tip position r(L), global components"),
        (_, "tip_angle") => ("rad", "tip angle from d3(0) towards d1(0), unfolded"),
        (_, "norm") => ("1/√m", "L² norm of the curvature, √∫|κ|² ds"),
        (_, "measures") => ("as each measure", "the named measures (columns as measure_names)"),
        (_, "shapes") => ("m", "centreline at equally spaced points"),
        (_, "shape_s") => ("m", "arc length of each shape point"),
        (_, "shape_d1" | "shape_d2" | "shape_d3") => ("1", "director d_i at the shape points, global components"),
        (_, "shape_curvature") => ("1/m", "curvature-twist κ at the shape points, body components"),
        (_, "shape_moment") => ("N·m", "internal moment M at the shape points, body components"),
        (_, "shape_force") => ("N", "internal force n at the shape points, global components"),
        (_, "unknowns") => ("", "discrete unknowns of the continued discretization"),
        (_, "tangent") => ("", "unit tangent of the branch in (unknowns, parameter)"),
        (_, "stable") => ("", "`stable` (Morse index 0 and conservative loads) or `unstable`"),
        (_, "held_keys") => ("", "keys held at the values of earlier stages"),
        (_, "held_values") => ("as each key", "values of the held keys"),
        ("special_points", "kind") => ("", "fold or branch point"),
        ("special_points", "branch" | "index") => ("", "branch and point index of the special point"),
        ("special_points", "block") => ("", "the Hessian block whose eigenvalue crosses zero"),
        ("special_points", "symmetry_breaking") => ("", "`breaking` where the mode breaks the branch's symmetry, else `preserving`"),
        ("special_points", "singularity") => ("1", "size of the singularity (test function, its bound)"),
        ("special_points", "multiplicity") => ("", "eigenvalues crossing zero together"),
        ("special_points", "location") => ("", "augmented (minimally augmented system), bracketed (regula falsi), interpolated (the test function's root interpolated from its samples on both sides where the corrector fails closer) or extrapolated (finite-element crossings on three meshes, Richardson)"),
        ("special_points", "parameter_error") => ("as the continued key", "estimated error of the parameter: augmented, the discretization's (the point located again on twice the collocation intervals or integration tolerances up to 100× tighter, Richardson-scaled; NaN with a warning where that failed); extrapolated, the difference of two extrapolations (the finite elements') plus the BVP discretization's part (the run's own mesh's crossing located again on the refined discretization, Richardson-scaled; NaN with a warning where that failed); bracketed, the bracket's spread where it was not closed; interpolated, the interpolants' difference (plus the discretization's where the refined family gives it); where it closed on a multiple branch point the discretization's (the root of the same entry of G located again on the refined discretization, Richardson-scaled), and on a fold of a branch of symmetric copies too (the root of τ_p bracketed again on the refined family's slice); NaN where not estimated: that relocation failed (a warning says why), or a fold or simple branch point kept bracketed (its augmented Newton failed, with a warning), or a simple branch point on a branch of symmetric copies"),
        (_, "warnings") => ("", "events detected but not located, and other warnings"),
        // Spatial arms (`/spatial`).
        ("spatial", "intrinsic_curvature") => ("1/m", "intrinsic curvature κ⁰(s) of the design, body components"),
        ("spatial", "design") => ("1", "the searched design vector: c2..cM, κ̄1 and κ̄3 coefficients, roll"),
        ("spatial", "bend_coefficients" | "bending_coefficients" | "twist_coefficients") => ("1", "Taylor coefficients of κ̄1, κ̄2, κ̄3 of the loaded shape (per rod length)"),
        ("spatial", "roll") => ("rad", "roll of the clamp about the chord"),
        ("spatial", "clamp_frame") => ("1", "clamp frame, columns d1(0), d2(0), d3(0)"),
        ("directions", "alpha") => ("rad", "reach direction α above the horizontal"),
        ("directions", "planar_reach" | "spatial_reach") => ("1", "R* per rod length of the planar or spatial optimum"),
        ("directions", "planar_error" | "spatial_error") => ("1", "Richardson estimate of the mesh error of R* (NaN: undecided)"),
        ("directions", "loading_path") => ("", "loading-path verdict of the spatial optimum: reaches, misses or undecided"),
        ("spatial" | "directions", "loading_path_end") => ("1", "load factor (× design load) where the loading path ended or lost stability"),
        // Arm studies.
        (_, "curvature_coefficients" | "shape_coefficients") => ("1", "Taylor coefficients of the loaded shape (per rod length)"),
        (_, "gamma_crit") => ("1", "critical load factor γ = w L³/B of the design"),
        (_, "intrinsic_curvature") => ("1/m", "intrinsic curvature κ⁰₂(s) of the design"),
        (_, "loaded_shape" | "unloaded_shape") => ("m", "centreline of the design, loaded or unloaded"),
        (_, "reach" | "reach_fine") => ("1", "reach per rod length L"),
        (_, "reach_error") => ("1", "estimated mesh error of the reach"),
        (_, "mesh_elements") => ("", "elements of the meshes of the convergence study"),
        (_, "reach_meshes") => ("1", "reach per rod length on each mesh of the convergence study"),
        (_, "rejected_elements") => ("", "elements of the mesh of each design given up"),
        (_, "rejected_reach") => ("1", "reach per rod length of each design given up: on its mesh, on 4× its elements"),
        (_, "reach_order") => ("1", "measured order of the mesh convergence"),
        (_, "reach_limit") => ("1", "mesh-converged optimum R*(N → ∞) per rod length: Richardson's limit of the optimum on three meshes of order-2 elements"),
        (_, "reach_limit_bound") => ("1", "error bound of reach_limit: the finest order-2 mesh's estimated error (NaN: undecided)"),
        (_, "limit_elements") => ("", "elements of the order-2 meshes of reach_limit"),
        (_, "limit_meshes") => ("1", "the optimum's reach per rod length on each order-2 mesh of reach_limit"),
        (_, "element_order") => ("", "Lagrange order of the elements of the mesh the result was computed on"),
        (_, "clamp_angle") => ("rad", "clamp angle of the straight arm"),
        (_, "leader_points") => ("1", "the best samples' coefficients"),
        (_, "leader_reach") => ("1", "the best samples' reach per rod length"),
        // Tapered arms.
        (_, "section") => ("1", "section area A at the knots, in units of the prismatic section (unit volume)"),
        (_, "section_knots") => ("1", "arc length of the section's knots per rod length"),
        (_, "min_section") => ("1", "lower bound A_min of the section, in units of the prismatic section"),
        (_, "loading_path_value") => ("1", "the loading path's number: load factor of the loss of stability, tip miss per L, or where it ended"),
        (_, "projected_gradient") => ("1", "max_i |x_i − P(x + ∇R̂)_i| of the joint ascent at the optimum (its stationarity)"),
        (_, "section_profile") => ("1", "section area A at the shape points, in units of the prismatic section"),
        // Sweeps.
        ("grid", "keys") => ("", "the --set key of each axis"),
        ("grid", "shape") => ("", "points along each axis"),
        ("grid", n) if n.starts_with("axis_") => ("as the axis key", "values along the axis"),
        ("points", "parameters") => ("as the axis keys", "the grid values of each point"),
        (_, "iterations") => ("", "Newton iterations"),
        (_, "residual") => ("1", "final scaled residual"),
        (_, "status") => ("", "what happened at the point"),
        ("points", "index") => ("", "grid index of each point (row-major)"),
        (_, "index") => ("", "index of the sample in the map"),
        (_, "curvature_norm") => ("1", "Σ b_k² of the design's curvature coefficients"),
        (_, "elements") => ("", "finite elements of the mesh the result was computed on"),
        (_, "evaluations") => ("", "designs evaluated"),
        (_, "mesh") => ("", "mesh-convergence verdict"),
        (_, "start") => ("", "how the point started: warm from its predecessor, or cold"),
        (_, "limit") => ("", "what limits the straight arm"),
        _ => ("", UNDESCRIBED),
    }
}

/// (units, description) of a dataset of `/curve` (curves of singular
/// points), None for one the other groups share (`unknowns`, `tangent`,
/// `warnings`, …).
#[rustfmt::skip]
fn curve_entry(name: &str) -> Option<(&'static str, &'static str)> {
    match name {
        "parameters" => Some(("as the two keys", "the two parameters along the curve")),
        "singularity" => Some(("1", "the test function along the curve")),
        "cusps" => Some(("", "point indices of the cusps")),
        "cusp_parameters" => Some(("as the two keys", "the two parameters at each cusp")),
        "parameter_error" => Some(("as the two keys", "estimated discretization errors of (p₁ at the point's p₂, p₂ at its p₁): the point located again on twice the collocation intervals or integration tolerances up to 100× tighter, with the parameter the curve moves along most held, the other's shift Richardson-scaled, the held one's through the curve's slope (inf where the curve runs parallel to its axis); NaN where that failed (a warning says why)")),
        "cusp_parameter_error" => Some(("as the two keys", "estimated discretization errors of each cusp's two parameters: the cusp located again between the refined curve's points around it, Richardson-scaled; NaN where that failed (a warning says why)")),
        _ => None,
    }
}

/// Whether a sweep result column (`family_0/evaluations`) holds a count:
/// stored as integers, not floats (docs/hdf5-schema.md, "Types").
pub fn is_count_column(name: &str) -> bool {
    let last = name.rsplit('/').next().unwrap_or(name);
    matches!(
        last,
        "iterations" | "elements" | "evaluations" | "element_order"
    )
}

/// Describes every dataset of a file's tree and stamps the schema version
/// on its root.
pub(crate) fn describe_file(root: &mut Group) {
    root.each_dataset_mut("", &mut |parent, name, ds| {
        let (units, description) = entry(parent, name);
        ds.attrs.set_text("units", units);
        ds.attrs.set_text("description", description);
    });
    root.attrs.set_text("schema_version", SCHEMA_VERSION);
}
