//! The arm optimizer's own guarantees (issue 18 item 5): the search runs
//! its samples and polishes in parallel yet gives the same optimum bit for
//! bit on one thread and on two, and a search interrupted anywhere and
//! resumed from its progress ends on the uninterrupted run's optimum.
//!
//! The problem is the paper's Fig. 5 arm (circular section, M = 4, bounds
//! (60)) with a short search, so that each run takes a fraction of a second
//! in release; the tests are ignored in debug builds (CI's `cargo test`).

use std::cell::Cell;
use std::path::Path;

use cosserat::input::Problem;
use cosserat::study::arm::{
    ArmOptimum, ArmProblem, ArmScene, MeshStudy, SearchOptions, SearchProgress,
};

/// The Fig. 5 arm of problems/longest_arm_fig5.toml with a short search.
fn fig5_arm() -> (ArmProblem, ArmScene, SearchOptions) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../problems/longest_arm_fig5.toml"
    );
    let problem = Problem::from_path(Path::new(path), &[]).expect("the shipped problem reads");
    let (arm, _, _) = problem.arm.clone().expect("an [arm] problem");
    let (scene, _) = problem.arm_scene.expect("an [arm] problem has a scene");
    let search = SearchOptions {
        samples: 96,
        starts: 3,
        iterations: 120,
    };
    (arm, scene, search)
}

/// The search's result reduced to bits: R̂, γ, c1..cM and the evaluations.
fn fingerprint(optimum: &ArmOptimum) -> (u64, u64, Vec<u64>, usize) {
    let d = &optimum.design;
    (
        d.reach.to_bits(),
        d.gamma.to_bits(),
        d.shape_coefficients.iter().map(|c| c.to_bits()).collect(),
        optimum.evaluations,
    )
}

/// A stop test that turns true at its `calls`-th call.
fn stop_after(calls: usize) -> impl Fn() -> bool {
    let seen = Cell::new(0);
    move || {
        seen.set(seen.get() + 1);
        seen.get() >= calls
    }
}

fn search(
    arm: &ArmProblem,
    scene: &ArmScene,
    opts: &SearchOptions,
    progress: SearchProgress,
    stop: &dyn Fn() -> bool,
) -> (Option<ArmOptimum>, SearchProgress, bool) {
    arm.search(scene, opts, progress, stop, &mut |_| {})
}

/// One thread and two give the same optimum, bit for bit, and the same
/// progress (samples, leaders, polishes, evaluations).
#[test]
#[cfg_attr(debug_assertions, ignore = "a search per thread count: release only")]
fn search_is_the_same_on_one_and_two_threads() {
    let (arm, scene, opts) = fig5_arm();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| search(&arm, &scene, &opts, SearchProgress::default(), &|| false))
    };
    let (one, one_progress, one_stopped) = on(1);
    let (two, two_progress, two_stopped) = on(2);
    assert!(!one_stopped && !two_stopped);
    let (one, two) = (one.expect("an optimum"), two.expect("an optimum"));
    assert_eq!(fingerprint(&one), fingerprint(&two));
    assert_eq!(one_progress, two_progress);
    assert_eq!(one.resolution, two.resolution);
}

/// Interrupted at several moments (in the samples, in the polishes) and
/// resumed from the progress it kept, the search ends on the optimum of an
/// uninterrupted run, bit for bit.
#[test]
#[cfg_attr(debug_assertions, ignore = "several searches: release only")]
fn resumed_search_ends_on_the_uninterrupted_optimum() {
    let (arm, scene, opts) = fig5_arm();
    let (whole, _, _) = search(&arm, &scene, &opts, SearchProgress::default(), &|| false);
    let whole = fingerprint(&whole.expect("an optimum"));
    let mut interruptions = 0;
    for calls in [1, 2, 3, 20, 200, 2000] {
        let (_, progress, interrupted) = search(
            &arm,
            &scene,
            &opts,
            SearchProgress::default(),
            &stop_after(calls),
        );
        if !interrupted {
            continue;
        }
        interruptions += 1;
        let (resumed, _, stopped) = search(&arm, &scene, &opts, progress, &|| false);
        assert!(!stopped);
        assert_eq!(
            fingerprint(&resumed.expect("an optimum")),
            whole,
            "resumed after {calls} stop tests"
        );
    }
    assert!(interruptions >= 4, "only {interruptions} runs interrupted");
}

/// Richardson's limit of a sequence with a known limit: R_N = R∞ + C N⁻² +
/// D N⁻⁴ (the form of a conforming element's eigenvalue error). The limit
/// is within the stated bound of R∞, and the bound is below the finest
/// mesh's own error.
#[test]
fn converged_reach_of_a_known_sequence() {
    let (limit, c, d) = (3.7, 0.6, 50.0);
    let at = |n: usize| limit + c / (n as f64).powi(2) + d / (n as f64).powi(4);
    let study = MeshStudy {
        elements: [100, 200, 400],
        reach: [at(100), at(200), at(400)],
        local_optima: false,
    };
    let (extrapolated, bound) = study.converged().expect("geometric differences");
    assert!(
        (extrapolated - limit).abs() <= bound,
        "{extrapolated} ± {bound}"
    );
    assert!(bound <= (at(400) - limit).abs() * 1.01, "bound {bound}");
    // Differences that do not shrink give no limit (undecided, not a value).
    let stalled = MeshStudy {
        reach: [3.0, 3.1, 3.0],
        ..study
    };
    assert_eq!(stalled.converged(), None);
}

/// On the arm: the limit from 25, 50 and 100 elements against the design's
/// reach on 1600 elements (an independent, finer computation): they agree
/// within the stated bound plus the 1600-element value's own error (≤ the
/// 100-element error / 256 at order 2).
#[test]
#[cfg_attr(debug_assertions, ignore = "1600-element critical loads: release only")]
fn converged_reach_agrees_with_a_fine_mesh() {
    let (arm, scene, _) = fig5_arm();
    let on = |elements: usize| {
        let mut a = arm.clone();
        a.stability = a.stability.with_elements(elements).expect("a valid mesh");
        a
    };
    let coarse = on(25);
    let design = (1..)
        .find_map(|i| coarse.design_in(&scene, &coarse.sample_point(i)))
        .expect("a feasible sample");
    let (study, _) = coarse.mesh_study(&scene, &design, 0);
    let (limit, bound) = study.converged().expect("the order is measured");
    let fine = on(1600)
        .design_in(&scene, &design.shape_coefficients[1..])
        .expect("the design is feasible on the fine mesh")
        .reach;
    let fine_error = (study.reach[2] - limit).abs() / 256.0;
    assert!(
        (limit - fine).abs() <= bound + fine_error,
        "limit {limit} ± {bound} against {fine} on 1600 elements (study {:?})",
        study.reach
    );
}
