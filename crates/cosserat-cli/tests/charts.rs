//! Charts fit for a paper, checked on the SVG they write: the visible text
//! speaks the problem's terms (no internal key), legends lie outside the
//! plotting areas, rod shapes are to scale (the pixels per unit of the two
//! axes, read from the tick labels, agree), the tags of marked points do
//! not overlap, colour bars accompany colour, no panel is empty, and PNG
//! and SVG are both written. The geometry is read back from the SVG text
//! (an independent reader of what was drawn), not from the layout code.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::problems::shipped;
use common::run::{run, scratch, stderr};
use cosserat::continuation::RunState;
use cosserat::output::SweepHeader;
use cosserat::study::sweep::Record;
use cosserat_cli::plot::{draw, BranchData, DiagramData, ProblemView, SpecialData};

fn dir(name: &str) -> PathBuf {
    scratch("charts", name)
}

/// A `<text>` element: its anchor point, alignment, size and content.
#[derive(Debug)]
struct SvgText {
    x: f64,
    y: f64,
    anchor: String,
    size: f64,
    text: String,
}

/// A `<rect>` element.
#[derive(Debug, Clone, Copy)]
struct SvgRect {
    x: f64,
    y: f64,
    w: f64,
    h: f64,
}

impl SvgRect {
    fn overlaps(&self, o: &SvgRect) -> bool {
        self.x < o.x + o.w && o.x < self.x + self.w && self.y < o.y + o.h && o.y < self.y + self.h
    }
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

fn number(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Every element `<name …>` of the SVG as (its opening tag, the text up to
/// its closing tag).
fn elements<'a>(svg: &'a str, name: &str) -> Vec<(&'a str, &'a str)> {
    let open = format!("<{name} ");
    let close = format!("</{name}>");
    let mut out = vec![];
    let mut rest = svg;
    while let Some(i) = rest.find(&open) {
        let from = &rest[i..];
        let end = from.find('>').unwrap();
        let tag = &from[..=end];
        let body_end = from.find(&close).unwrap_or(end + 1).max(end + 1);
        out.push((tag, &from[end + 1..body_end]));
        rest = &from[end + 1..];
    }
    out
}

fn texts(svg: &str) -> Vec<SvgText> {
    elements(svg, "text")
        .into_iter()
        .map(|(tag, body)| SvgText {
            x: number(tag, "x"),
            y: number(tag, "y"),
            anchor: attr(tag, "text-anchor").unwrap_or("start").to_string(),
            size: number(tag, "font-size"),
            text: body.trim().to_string(),
        })
        .collect()
}

fn rects(svg: &str, fill: &str, stroke: &str) -> Vec<SvgRect> {
    elements(svg, "rect")
        .into_iter()
        .filter(|(tag, _)| attr(tag, "fill") == Some(fill) && attr(tag, "stroke") == Some(stroke))
        .map(|(tag, _)| SvgRect {
            x: number(tag, "x"),
            y: number(tag, "y"),
            w: number(tag, "width"),
            h: number(tag, "height"),
        })
        .collect()
}

/// The plotting areas: the black unfilled frames (markers are smaller).
fn frames(svg: &str) -> Vec<SvgRect> {
    rects(svg, "none", "#000000")
        .into_iter()
        .filter(|r| r.w > 40.0 && r.h > 40.0)
        .collect()
}

/// The legend boxes (grey border).
fn legends(svg: &str) -> Vec<SvgRect> {
    rects(svg, "none", "#808080")
}

/// No internal name in any visible text.
fn assert_problem_terms(svg: &str) {
    for t in texts(svg) {
        for key in [
            "energy.",
            "loads.",
            "load.",
            "[0]",
            "[1]",
            "[2]",
            "_scale",
            "tip_",
            "stiffness",
            "family_",
        ] {
            assert!(
                !t.text.contains(key),
                "internal name `{key}` in {:?}",
                t.text
            );
        }
    }
}

fn assert_legends_outside(svg: &str) {
    let legends = legends(svg);
    assert!(!legends.is_empty(), "a legend");
    for l in &legends {
        for f in frames(svg) {
            assert!(!l.overlaps(&f), "legend {l:?} over the plotting area {f:?}");
        }
    }
}

/// Pixels per data unit of the x and y axes of `frame`, from its tick
/// labels (x ticks centred below it, y ticks right-aligned left of it).
fn pixels_per_unit(svg: &str, frame: &SvgRect) -> (f64, f64) {
    let all = texts(svg);
    let fit = |ticks: Vec<(f64, f64)>| {
        assert!(ticks.len() >= 2, "ticks {ticks:?}");
        let (a, b) = (ticks[0], ticks[ticks.len() - 1]);
        (b.1 - a.1) / (b.0 - a.0)
    };
    let x_ticks: Vec<(f64, f64)> = all
        .iter()
        .filter(|t| t.anchor == "middle")
        .filter(|t| t.y > frame.y + frame.h && t.y < frame.y + frame.h + 30.0)
        .filter(|t| t.x >= frame.x - 1.0 && t.x <= frame.x + frame.w + 1.0)
        .filter_map(|t| t.text.parse::<f64>().ok().map(|v| (v, t.x)))
        .collect();
    let y_ticks: Vec<(f64, f64)> = all
        .iter()
        .filter(|t| t.anchor == "end")
        .filter(|t| t.x < frame.x && t.x > frame.x - 30.0)
        .filter(|t| t.y >= frame.y - 1.0 && t.y <= frame.y + frame.h + 1.0)
        .filter_map(|t| t.text.parse::<f64>().ok().map(|v| (v, t.y)))
        .collect();
    (fit(x_ticks).abs(), fit(y_ticks).abs())
}

fn assert_to_scale(svg: &str, frame: &SvgRect) {
    let (sx, sy) = pixels_per_unit(svg, frame);
    assert!(
        (sx / sy - 1.0).abs() < 0.02,
        "x {sx} px/unit, y {sy} px/unit: not to scale"
    );
}

/// The boxes of the marked points' tags (F1, BP2, E3, "BP1, BP2").
fn tag_boxes(svg: &str) -> Vec<(String, SvgRect)> {
    let is_tag = |s: &str| {
        s.split(", ").all(|t| {
            let digits = t.trim_start_matches(|c: char| c.is_ascii_uppercase());
            digits.len() < t.len()
                && !digits.is_empty()
                && digits.chars().all(|c| c.is_ascii_digit())
                && ["F", "BP", "E", "S", "P", "Q"].contains(&&t[..t.len() - digits.len()])
        })
    };
    texts(svg)
        .into_iter()
        .filter(|t| is_tag(&t.text))
        .map(|t| {
            // DejaVu Sans advance widths (em), rounded up.
            let em: f64 = t
                .text
                .chars()
                .map(|c| match c {
                    ',' | ' ' => 0.33,
                    '0'..='9' => 0.64,
                    _ => 0.70,
                })
                .sum();
            let w = em * t.size;
            let r = SvgRect {
                x: t.x,
                y: t.y,
                w,
                h: t.size,
            };
            (t.text, r)
        })
        .collect()
}

fn assert_tags_apart(svg: &str) {
    let tags = tag_boxes(svg);
    for (i, a) in tags.iter().enumerate() {
        for b in &tags[i + 1..] {
            assert!(!a.1.overlaps(&b.1), "tags {a:?} and {b:?} overlap");
        }
    }
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{} is a PNG",
        path.display()
    );
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

/// Euler's column (load factor λ = F L²/B against the tip's deflection):
/// both charts written, the labels the problem's, the legend beside the
/// diagram, the two branch points found at one load tagged apart, the
/// shapes to scale.
#[test]
fn continuation_chart_of_the_euler_column() {
    let d = dir("euler");
    let h5 = d.join("euler.h5");
    let svg = d.join("euler.svg");
    let png = d.join("euler.png");
    let o = run(&[
        "continue",
        &shipped("euler_column"),
        "-o",
        h5.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
        "--set",
        "continuation.bounds=[0,4]",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&["plot", h5.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_png(&png);
    let text = read(&svg);
    assert_problem_terms(&text);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    for label in [
        "load factor λ",
        "tip x/L",
        "height −x/L",
        "z/L",
        "stable",
        "unstable",
    ] {
        assert!(words.iter().any(|w| w == label), "`{label}` in {words:?}");
    }
    assert!(words.iter().any(|w| w == "branch point BP"));
    assert!(words.iter().any(|w| w == "tip force F"));
    assert_legends_outside(&text);
    let tags = tag_boxes(&text);
    for t in ["BP1", "BP2"] {
        assert!(tags.iter().any(|(s, _)| s == t), "{t} in {tags:?}");
    }
    assert_tags_apart(&text);
    // The shapes' frame is the right one.
    let frames = frames(&text);
    let shapes = frames.iter().max_by(|a, b| a.x.total_cmp(&b.x)).unwrap();
    assert_to_scale(&text, shapes);
    // --measure names a measure in its terms too.
    let angle = d.join("angle.svg");
    let o = run(&[
        "plot",
        h5.to_str().unwrap(),
        "-o",
        angle.to_str().unwrap(),
        "--measure",
        "tip_angle",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(texts(&read(&angle))
        .iter()
        .any(|t| t.text == "tip angle (°)"));
    std::fs::remove_dir_all(d).unwrap();
}

/// A branch with shapes `height` high and five special points within a
/// few pixels of each other, on a constant measure.
fn crowded_diagram(height: f64) -> DiagramData {
    let m = 20;
    let shape = |k: usize| -> Vec<[f64; 3]> {
        (0..=20)
            .map(|i| {
                let s = f64::from(i) / 20.0;
                [
                    -height * (std::f64::consts::PI * s).sin() * k as f64 / m as f64,
                    0.0,
                    s,
                ]
            })
            .collect()
    };
    let branch = BranchData {
        parameter: (0..m).map(|i| 1.0 + i as f64 * 0.1).collect(),
        tip: (0..m).map(|_| [0.25, 0.0, 1.0]).collect(),
        tip_angle: vec![0.0; m],
        norm: vec![1.0; m],
        stable: (0..m).map(|i| i < 10).collect(),
        shapes: (0..m).map(shape).collect(),
        measures: vec![vec![]; m],
    };
    let special = |kind: &str, index: usize, parameter: f64| SpecialData {
        kind: kind.into(),
        branch: 0,
        index,
        parameter,
        tip: [0.25, 0.0, 1.0],
        measures: vec![],
    };
    DiagramData {
        parameter_name: "loads.tip_force[2]".into(),
        branches: vec![branch],
        specials: vec![
            special("branch_point", 9, 1.95),
            special("branch_point", 9, 1.95),
            special("fold", 9, 1.951),
            special("fold", 10, 1.953),
            special("branch_point", 10, 1.96),
        ],
        measure_names: vec![],
    }
}

const UNIT_ROD: &str = "[rod]\nlength = 1.0\n[energy]\nstiffness = [1.0, 1.0, 0.7]\n\
                        [loads]\ntip_force = [0.0, 0.0, -1.0]\n";

/// Tags of crowded special points are placed apart; a constant measure
/// gets a padded axis whose ticks differ; a very flat shape is still drawn
/// to scale; the continued load component is labelled F₃ L²/B₂.
#[test]
fn crowded_points_flat_shapes_and_a_constant_measure() {
    let d = dir("crowded");
    let data = crowded_diagram(0.02);
    let keep = std::env::var_os("CHARTS_KEEP").is_some();
    let view = ProblemView::of_problem(UNIT_ROD, &data.parameter_name);
    let svg = d.join("crowded.svg");
    draw(&data, &view, "tip_x", &svg).unwrap();
    let png = d.join("crowded.png");
    draw(&data, &view, "tip_x", &png).unwrap();
    assert_png(&png);
    let text = read(&svg);
    assert_problem_terms(&text);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    assert!(words.iter().any(|w| w == "F₃ L²/B₂"), "{words:?}");
    for t in ["BP1", "BP2", "BP3", "F1", "F2", "E1"] {
        assert!(tag_boxes(&text).iter().any(|(s, _)| s == t), "{t}");
    }
    assert_tags_apart(&text);
    assert_legends_outside(&text);
    let frames = frames(&text);
    let (diagram, shapes) = (
        frames.iter().min_by(|a, b| a.x.total_cmp(&b.x)).unwrap(),
        frames.iter().max_by(|a, b| a.x.total_cmp(&b.x)).unwrap(),
    );
    // The constant tip x = 0.25: distinct ticks around it.
    let (_, sy) = pixels_per_unit(&text, diagram);
    assert!(sy.is_finite() && sy > 0.0);
    assert_to_scale(&text, shapes);
    // A problem in other units is labelled in the documented units.
    let view = ProblemView::of_problem(
        &UNIT_ROD.replace("length = 1.0", "length = 2.0"),
        "loads.tip_force[2]",
    );
    draw(&data, &view, "tip_x", &svg).unwrap();
    let words: Vec<String> = texts(&read(&svg)).into_iter().map(|t| t.text).collect();
    assert!(words.iter().any(|w| w == "F₃ (N)") && words.iter().any(|w| w == "tip x (m)"));
    if !keep {
        std::fs::remove_dir_all(d).unwrap();
    }
}

const ARM: &str = "[rod]\nlength = 1.0\n[energy]\nstiffness = [4.0, 1.0, 1.27]\n\
                   [loads]\ntip_force = [1.0, 0.0, 0.0]\n[arm]\ncoefficients = 3\n";

fn header(keys: &[&str], axes: Vec<Vec<f64>>) -> SweepHeader {
    SweepHeader {
        problem: ARM.into(),
        kind: "arm".into(),
        shard: "merged".into(),
        stop_reason: RunState::Completed,
        keys: keys.iter().map(ToString::to_string).collect(),
        members: axes.iter().map(Vec::len).product(),
        axes,
    }
}

fn record(index: usize, numbers: &[(&str, f64)], labels: &[(&str, &str)]) -> Record {
    let mut r = Record::new(index);
    r.numbers = numbers
        .iter()
        .map(|(k, v)| (k.to_string(), vec![*v]))
        .collect::<BTreeMap<_, _>>();
    r.labels = labels
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    r
}

/// Fig. 6 on a 4 × 3 grid where family 1 has no optimum anywhere: one
/// map (no empty panel, a note instead), its colour bar, labels B₁/B₂ and
/// B₃/B₂, the legend of contours and fit above the map.
#[test]
fn reach_map_has_a_colour_bar_and_no_empty_panel() {
    let d = dir("map");
    let (b1, b3) = (vec![0.5, 1.0, 2.0, 4.0], vec![0.5, 1.0, 2.0]);
    let h = header(
        &["energy.stiffness[0]", "energy.stiffness[2]"],
        vec![b1.clone(), b3.clone()],
    );
    let records: Vec<Record> = (0..12)
        .map(|i| {
            let reach = 1.0 + b1[i / 3] * b3[i % 3];
            record(
                i,
                &[("family_0/reach", reach), ("family_1/reach", f64::NAN)],
                &[
                    ("family_0/status", "optimum"),
                    ("family_1/status", "not_found"),
                ],
            )
        })
        .collect();
    for ext in ["svg", "png"] {
        let out = d.join(format!("map.{ext}"));
        cosserat_cli::sweep_figure::draw(&out, &h, &records).unwrap();
        assert!(out.exists());
    }
    assert_png(&d.join("map.png"));
    let text = read(&d.join("map.svg"));
    assert_problem_terms(&text);
    assert_legends_outside(&text);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    for label in ["B₁/B₂", "B₃/B₂", "R* √(F/B₂)", "R*, family 0"] {
        assert!(words.iter().any(|w| w == label), "`{label}` in {words:?}");
    }
    assert!(!words.iter().any(|w| w == "R*, family 1"), "no empty panel");
    assert!(words
        .iter()
        .any(|w| w.starts_with("family 1: no distinct optimum")));
    // The colour bar: a column of many shaded steps of one x and width.
    let mut columns: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    for (tag, _) in elements(&text, "rect") {
        if attr(tag, "stroke") == Some("none") && attr(tag, "fill") != Some("#FFFFFF") {
            *columns
                .entry((number(tag, "x") as i64, number(tag, "width") as i64))
                .or_default() += 1;
        }
    }
    assert!(
        columns.values().any(|n| *n >= 90),
        "a colour bar: {columns:?}"
    );
    // Map and colour bar: two plotting areas.
    assert_eq!(frames(&text).len(), 2);
    std::fs::remove_dir_all(d).unwrap();
}

/// Fig. 7 on two stiffnesses and three directions: both panels to scale,
/// the legend beside them, curves labelled B₁/B₂ = ….
#[test]
fn reach_envelopes_are_to_scale_with_the_legend_aside() {
    let d = dir("envelopes");
    let alpha = vec![90.0, 45.0, 0.0];
    let h = header(
        &["energy.stiffness[0]", "arm.alpha"],
        vec![vec![1.0, 4.0], alpha],
    );
    let records: Vec<Record> = (0..6)
        .map(|i| {
            let r = if i < 3 {
                1.6 + 0.1 * i as f64
            } else {
                1.6 + 1.0 * (i - 3) as f64
            };
            record(i, &[("family_0/reach", r), ("straight/reach", 1.5)], &[])
        })
        .collect();
    let out = d.join("envelopes.svg");
    cosserat_cli::sweep_figure::draw(&out, &h, &records).unwrap();
    let png = d.join("envelopes.png");
    cosserat_cli::sweep_figure::draw(&png, &h, &records).unwrap();
    assert_png(&png);
    let text = read(&out);
    assert_problem_terms(&text);
    assert_legends_outside(&text);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    for label in ["B₁/B₂ = 1", "B₁/B₂ = 4", "horizontal reach z √(F/B₂)"] {
        assert!(words.iter().any(|w| w == label), "`{label}` in {words:?}");
    }
    let frames = frames(&text);
    assert_eq!(frames.len(), 2);
    for f in &frames {
        assert_to_scale(&text, f);
    }
    std::fs::remove_dir_all(d).unwrap();
}

/// The shipped work-precision measurement redrawn: PNG and SVG, the
/// legend above the panels.
#[test]
fn work_precision_chart_redrawn_from_its_csv() {
    let d = dir("bench");
    let stored = |name: &str| format!("{}/docs/work-precision/{name}", common::problems::ROOT);
    let redraw = |csvs: &[String]| {
        let mut args = vec!["bench".to_string(), "work-precision".to_string()];
        for c in csvs {
            args.extend(["--redraw".to_string(), c.clone()]);
        }
        args.extend(["-o".to_string(), d.to_str().unwrap().to_string()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        read(&d.join("work_precision.svg"))
    };
    let text = redraw(&[stored("work_precision.csv")]);
    assert_png(&d.join("work_precision.png"));
    assert_legends_outside(&text);
    assert_eq!(frames(&text).len(), 3);
    // With scipy's points (scripts/scipy_work_precision.py) beside them:
    // one more legend entry, the same panels.
    let text = redraw(&[stored("work_precision.csv"), stored("scipy_solve_bvp.csv")]);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    assert!(words.iter().any(|w| w == "scipy solve_bvp"), "{words:?}");
    assert_legends_outside(&text);
    assert_eq!(frames(&text).len(), 3);
    // A file that is not such a CSV is bad input, named.
    let o = run(&[
        "bench",
        "work-precision",
        "--redraw",
        &shipped("euler_column"),
        "-o",
        d.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a work_precision.csv header"));
    std::fs::remove_dir_all(d).unwrap();
}

/// An arm design of reach `reach` whose loaded shape is a quarter circle
/// bent down to the tip and whose unloaded shape rises.
fn arm_design(reach: f64, c: [f64; 3], b: [f64; 2]) -> cosserat::study::arm::ArmOptimum {
    use cosserat::study::arm::{ArmDesign, ArmOptimum, ArmScene};
    let arc = |sign: f64| -> Vec<[f64; 3]> {
        (0..=40)
            .map(|i| {
                let t = std::f64::consts::FRAC_PI_2 * f64::from(i) / 40.0;
                [sign * reach * (1.0 - t.cos()), 0.0, reach * t.sin()]
            })
            .collect()
    };
    ArmOptimum {
        design: ArmDesign {
            reach,
            gamma: 4.0,
            shape_coefficients: vec![0.0, c[0], c[1], c[2]],
        },
        curvature_coefficients: b.to_vec(),
        loaded_shape: arc(0.3),
        unloaded_shape: arc(-0.5),
        intrinsic_curvature: vec![],
        evaluations: 1,
        critical_load: 4.0,
        scene: ArmScene::default(),
        resolution: None,
        limit: None,
        mesh: cosserat::stability::StabilityOptions::default(),
    }
}

/// The Fig. 5 chart: two reach maps, each with its colour bar; P and Q
/// tagged apart; the shapes to scale with their legends above them.
#[test]
fn arm_chart_has_colour_bars_and_shapes_to_scale() {
    use cosserat::study::arm::{ClosestStraight, ReachMap};
    use cosserat_cli::arm_chart::{draw_arm, ArmChart};
    let d = dir("arm");
    let p = arm_design(1.9, [0.5, 0.2, 0.0], [-2.0, 2.8]);
    let q = ClosestStraight {
        index: 3,
        curvature_norm: 1.4,
        optimum: arm_design(1.85, [0.52, 0.21, 0.0], [-1.9, 2.7]),
    };
    let n = 300;
    let u = |k: usize, m: usize| ((k * m) % 997) as f64 / 997.0;
    let map = ReachMap {
        shape_coefficients: (0..n)
            .map(|k| vec![0.0, 8.0 * u(k, 31) - 4.0, 4.0 * u(k, 17) - 2.0, 0.0])
            .collect(),
        curvature_coefficients: (0..n)
            .map(|k| vec![6.0 * u(k, 13) - 4.0, 8.0 * u(k, 29) - 2.0])
            .collect(),
        reach: (0..n).map(|k| 1.0 + u(k, 7)).collect(),
        gamma: vec![4.0; n],
        samples: n,
        interrupted: false,
    };
    let chart = ArmChart {
        optimum: &p,
        map: Some(&map),
        closest: Some(&q),
        straight: None,
    };
    let (svg, png) = (d.join("arm.svg"), d.join("arm.png"));
    draw_arm(&chart, &svg).unwrap();
    draw_arm(&chart, &png).unwrap();
    assert_png(&png);
    let text = read(&svg);
    assert_problem_terms(&text);
    assert_legends_outside(&text);
    assert_tags_apart(&text);
    let words: Vec<String> = texts(&text).into_iter().map(|t| t.text).collect();
    for label in [
        "loaded-shape coefficient c₂",
        "R √(F/B₂)",
        "P loaded",
        "tip force F",
    ] {
        assert!(words.iter().any(|w| w == label), "`{label}` in {words:?}");
    }
    let mut columns: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    for (tag, _) in elements(&text, "rect") {
        if attr(tag, "stroke") == Some("none") && attr(tag, "fill") != Some("#FFFFFF") {
            *columns
                .entry((number(tag, "x") as i64, number(tag, "width") as i64))
                .or_default() += 1;
        }
    }
    assert_eq!(
        columns.values().filter(|n| **n >= 90).count(),
        2,
        "two colour bars"
    );
    let shapes: Vec<SvgRect> = frames(&text)
        .into_iter()
        .filter(|f| f.y > 600.0 && f.w > 100.0)
        .collect();
    assert_eq!(shapes.len(), 2);
    for f in &shapes {
        assert_to_scale(&text, f);
    }
    std::fs::remove_dir_all(d).unwrap();
}
