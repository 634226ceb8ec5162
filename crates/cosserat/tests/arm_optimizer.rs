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
use cosserat::study::arm::{ArmOptimum, ArmProblem, ArmScene, SearchOptions, SearchProgress};

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
