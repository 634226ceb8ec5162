//! Links the `cosserat` executable at a fixed address (`-no-pie`).
//!
//! A position-independent executable makes the dynamic loader apply one
//! relative relocation per pointer in its data (≈ 8600 for this binary)
//! and dirty the pages that hold them before `main` runs; linked at a
//! fixed address the linker resolves them once. `cosserat solve` is a
//! short process (issue 18: ≤ 2 ms whole), where that start-up is a
//! measurable share: callgrind 5.98 M → 5.86 M instructions and 289 → 266
//! page faults (docs/performance.md). The code is still compiled
//! position-independent (only the executables are linked this way, not
//! the libraries or the Python module), and the binary gives up address
//! randomization of its own image — acceptable for a batch tool that
//! reads problem files, not network input.
fn main() {
    println!("cargo:rustc-link-arg-bins=-no-pie");
}
