//! `sc-plot` and the pipeline's `plot` stage on small force CSVs written here: the
//! PNG has the requested size and is a real picture (text, grid, the series'
//! colours); bad input fails with the file, line or column named and no PNG.

use std::path::Path;

use crate::common::*;

/// A force history like sc-solve's: a press (V grows) then a slide (H/V ≈ 0.3),
/// with the indenter's reaction triple written twice (one set, two constraints).
fn forces_csv(rows: usize, v_max: f64) -> String {
    let mut s = String::from("increment,load_factor,reaction:base:x,reaction:base:y,reaction:base:z,reaction:top:x,reaction:top:y,reaction:top:z,reaction:top:x,reaction:top:y,reaction:top:z,active:contact\n");
    for k in 1..=rows {
        let t = 2.0 * k as f64 / rows as f64;
        let v = -v_max * t.min(1.0);
        let h = if t > 1.0 { -0.3 * v } else { 0.0 };
        s.push_str(&format!("{k},{t:e},0e0,{:e},0e0,{h:e},{v:e},0e0,9e9,9e9,9e9,{}\n", -v, k.min(7)));
    }
    s
}

/// Width and height from the IHDR chunk, and the number of distinct colours.
fn png_facts(path: &Path) -> (u32, u32, usize, Vec<[u8; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height, info.color_type), (w, h, png::ColorType::Rgb));
    let mut colours: Vec<[u8; 3]> = buf[..info.buffer_size()].chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    (w, h, colours.len(), colours)
}

const BLUE: [u8; 3] = [31, 119, 180];
const ORANGE: [u8; 3] = [255, 127, 14];

#[test]
fn sc_plot_writes_a_png_of_the_requested_size() {
    let dir = tempdir();
    std::fs::write(dir.path().join("facet.forces.csv"), forces_csv(40, 400.0)).unwrap();
    std::fs::write(dir.path().join("b3.forces.csv"), forces_csv(12, 380.0)).unwrap();
    let o = run(
        "sc-plot",
        &[
            "out.png", "--title", "Ironing: V", "--y-label", "V [N/mm]", "--size", "640", "480",
            "--series", "facet.forces.csv:reaction:top:y:-1", "--label", "facet",
            "--series", "b3.forces.csv:reaction:top:y:-1", "--label", "B-spline 3",
        ],
        dir.path(),
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("wrote out.png (640 × 480 px, 1 panel(s), 2 series, 52 points)"), "{err}");
    let (w, h, n, colours) = png_facts(&dir.path().join("out.png"));
    assert_eq!((w, h), (640, 480));
    // anti-aliased text and lines give many shades; a blank or text-less image a few
    assert!(n > 50, "only {n} distinct colours");
    assert!(colours.contains(&BLUE) && colours.contains(&ORANGE), "the two series' colours");
}

#[test]
fn sc_plot_divide_by_and_x_range() {
    let dir = tempdir();
    std::fs::write(dir.path().join("a.forces.csv"), forces_csv(20, 400.0)).unwrap();
    let o = run(
        "sc-plot",
        &["hv.png", "--divide-by", "reaction:top:y", "--x-range", "1", "2", "--series", "a.forces.csv:reaction:top:x:-1"],
        dir.path(),
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    // rows with t in [1, 2]: k = 10..=20
    assert!(err.contains("1 series, 11 points"), "{err}");
    let (w, h, n, _) = png_facts(&dir.path().join("hv.png"));
    assert_eq!((w, h), (1000, 700));
    assert!(n > 50, "only {n} distinct colours");
}

#[test]
fn pipeline_plot_stage_stacks_panels() {
    let dir = tempdir();
    std::fs::create_dir(dir.path().join("runs")).unwrap();
    std::fs::write(dir.path().join("runs/facet.forces.csv"), forces_csv(40, 400.0)).unwrap();
    std::fs::write(dir.path().join("runs/b3.forces.csv"), forces_csv(40, 390.0)).unwrap();
    let yaml = r#"version: 1
stages:
  - plot:
      output: out/forces.png
      title: "Shallow ironing, μ = 0.3: reaction on the indenter top"
      x_label: "pseudo-time t"
      panels:
        - y_label: "vertical force V [N/mm]"
          series:
            - {input: runs/facet.forces.csv, column: "reaction:top:y", scale: -1.0, label: facet}
            - {input: runs/b3.forces.csv, column: "reaction:top:y", scale: -1.0, label: "B-spline 3"}
        - y_label: "H/V"
          y_range: [0.0, 0.5]
          series:
            - {input: runs/facet.forces.csv, column: "reaction:top:x", divide_by: "reaction:top:y", scale: -1.0, label: facet}
"#;
    std::fs::create_dir(dir.path().join("p")).unwrap();
    std::fs::write(dir.path().join("p/plot.yaml"), yaml.replace("runs/", "../runs/")).unwrap();
    // run from elsewhere: the paths resolve against the YAML's folder
    let o = run("sc-pipeline", &["p/plot.yaml"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("[1/1] plot") && err.contains("2 panel(s), 3 series") && err.contains("pipeline finished"), "{err}");
    let (w, h, n, colours) = png_facts(&dir.path().join("p/out/forces.png"));
    assert_eq!((w, h), (1000, 1050), "default size for two panels");
    assert!(n > 50 && colours.contains(&BLUE) && colours.contains(&ORANGE), "{n} colours");
}

#[test]
fn sc_plot_missing_column_names_file_and_columns() {
    let dir = tempdir();
    std::fs::write(dir.path().join("a.forces.csv"), forces_csv(5, 1.0)).unwrap();
    let o = run("sc-plot", &["out.png", "--series", "a.forces.csv:reaction:indenter_top:y"], dir.path());
    assert_fails(
        &o,
        2,
        &["a.forces.csv", "no column 'reaction:indenter_top:y'", "(the file has: increment, load_factor, reaction:base:x,", "reaction:top:z, active:contact)"],
        &dir.path().join("out.png"),
    );
}

#[test]
fn sc_plot_bad_input_kinds() {
    let dir = tempdir();
    let bad_number = forces_csv(5, 1.0).replacen("\n3,", "\n3,x", 1);
    std::fs::write(dir.path().join("bad.forces.csv"), bad_number).unwrap();
    std::fs::write(dir.path().join("empty.forces.csv"), "").unwrap();
    std::fs::write(dir.path().join("header.forces.csv"), "increment,load_factor\n").unwrap();
    let out = dir.path().join("out.png");
    let o = run("sc-plot", &["out.png", "--series", "bad.forces.csv:active:contact"], dir.path());
    assert_fails(&o, 2, &["bad.forces.csv: line 4, column 'load_factor'", "\"x"], &out);
    let o = run("sc-plot", &["out.png", "--series", "empty.forces.csv:active:contact"], dir.path());
    assert_fails(&o, 2, &["empty.forces.csv: empty file"], &out);
    let o = run("sc-plot", &["out.png", "--series", "header.forces.csv:load_factor"], dir.path());
    assert_fails(&o, 2, &["header.forces.csv: has a header but no data rows"], &out);
    let o = run("sc-plot", &["out.png", "--series", "nowhere.forces.csv:load_factor"], dir.path());
    assert_fails(&o, 1, &["nowhere.forces.csv: cannot read"], &out);
    let o = run("sc-plot", &["out.svg", "--series", "bad.forces.csv:load_factor"], dir.path());
    assert_fails(&o, 2, &["out.svg: the output must be a .png"], &dir.path().join("out.svg"));
}

#[test]
fn pipeline_plot_stage_failure_keeps_the_old_png() {
    let dir = tempdir();
    std::fs::write(dir.path().join("a.forces.csv"), forces_csv(5, 1.0)).unwrap();
    std::fs::write(dir.path().join("old.png"), b"previous").unwrap();
    let yaml = "version: 1\nstages:\n  - plot:\n      output: old.png\n      panels:\n        - series:\n            - {input: a.forces.csv, column: \"contact:contact:z\"}\n";
    std::fs::write(dir.path().join("p.yaml"), yaml).unwrap();
    let o = run("sc-pipeline", &["p.yaml"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("stage 1 (plot) failed") && err.contains("a.forces.csv: no column 'contact:contact:z'"), "{err}");
    assert_eq!(std::fs::read(dir.path().join("old.png")).unwrap(), b"previous");
}
