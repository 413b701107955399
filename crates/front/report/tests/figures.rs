//! Figures, panels and heat maps: files written, sizes, ranges, and no
//! panics on awkward input.

mod common;

use autoshovel_report::*;
use common::{png_size, read_svg, Scratch};

fn sample_figure() -> Figure {
    let path: Vec<(f64, f64)> = (0..100)
        .map(|i| {
            let t = f64::from(i) * 0.1;
            (t, t.sin())
        })
        .collect();
    Figure::new("Tracking <test> & more", "time [s]", "deviation [m]")
        .layer(Layer::line(path.clone(), Stroke::solid(Rgb::BLUE, 2)).with_label("planned"))
        .layer(
            Layer::line(
                path.iter().map(|p| (p.0, p.1 + 0.1)),
                Stroke::dashed(Rgb::RED, 2),
            )
            .with_label("actual"),
        )
        .layer(Layer::points(vec![(0.0, 0.0), (5.0, 0.5)], Rgb::GREEN, 4).with_label("marks"))
        .layer(
            Layer::circle((3.0, 0.0), 0.5, Some(Rgb::GREY), Stroke::default())
                .with_label("obstacle"),
        )
        .layer(
            Layer::polygon(
                vec![(6.0, -0.5), (7.0, -0.5), (6.5, 0.2)],
                Some(Rgb::ORANGE),
                Stroke::solid(Rgb::BROWN, 1),
            )
            .with_label("zone"),
        )
        .layer(
            Layer::arrow((1.0, -0.8), (2.0, -0.3), Stroke::solid(Rgb::PURPLE, 2))
                .with_label("heading"),
        )
        .layer(Layer::text((8.0, 0.8), "note", Rgb::BLACK))
}

#[test]
fn figure_writes_svg_and_png_of_the_requested_size() {
    let dir = Scratch::new("figure_files");
    let fig = sample_figure().size(640, 480);
    let [svg, png] = write_figure(&fig, dir.path(), "tracking").unwrap();
    assert_eq!(svg, dir.path().join("tracking.svg"));
    assert_eq!(png, dir.path().join("tracking.png"));
    let text = read_svg(&svg);
    assert!(
        text.contains("Tracking &lt;test&gt; &amp; more"),
        "title in SVG"
    );
    assert!(
        text.contains("sans-serif"),
        "SVG text uses the sans-serif family"
    );
    for label in [
        "planned", "actual", "marks", "obstacle", "zone", "heading", "note",
    ] {
        assert!(text.contains(label), "{label} in SVG");
    }
    assert_eq!(png_size(&png), (640, 480));
}

#[test]
fn default_size_is_900_by_700() {
    let dir = Scratch::new("figure_default_size");
    let fig = Figure::new("t", "x", "y")
        .layer(Layer::line(vec![(0.0, 0.0), (1.0, 1.0)], Stroke::default()));
    assert_eq!((fig.width_px, fig.height_px), (900, 700));
    let [_, png] = write_figure(&fig, dir.path(), "f").unwrap();
    assert_eq!(png_size(&png), (900, 700));
}

#[test]
fn panels_stack_vertically() {
    let dir = Scratch::new("panels");
    let a = Figure::new("Deviation", "t [s]", "e [m]")
        .size(800, 300)
        .layer(Layer::line(
            vec![(0.0, 0.1), (10.0, -0.1)],
            Stroke::solid(Rgb::BLUE, 2),
        ));
    let b = Figure::new("Heading", "t [s]", "psi [rad]")
        .size(700, 350)
        .layer(Layer::line(
            vec![(0.0, 1.0), (10.0, 1.2)],
            Stroke::solid(Rgb::RED, 2),
        ));
    let [svg, png] = write_panels(&[a, b], dir.path(), "panels").unwrap();
    let text = read_svg(&svg);
    assert!(text.contains("Deviation") && text.contains("Heading"));
    assert_eq!(png_size(&png), (800, 650));
    assert!(matches!(
        write_panels(&[], dir.path(), "none"),
        Err(ReportError::Invalid { .. })
    ));
}

#[test]
fn equal_aspect_matches_plotting_area() {
    let fig = Figure::new("map", "east [m]", "north [m]")
        .equal_aspect()
        .layer(Layer::points(vec![(0.0, 0.0), (100.0, 10.0)], Rgb::BLUE, 3));
    let ((x0, x1), (y0, y1)) = data_ranges(&fig).unwrap();
    let (pw, ph) = plot_area_px(fig.width_px, fig.height_px);
    let aspect = f64::from(pw) / f64::from(ph);
    assert!(((x1 - x0) / (y1 - y0) - aspect).abs() < 1e-9);
    assert!(
        x0 < 0.0 && x1 > 100.0 && y0 < 0.0 && y1 > 10.0,
        "data still inside"
    );

    // Tall data: x is the one padded.
    let tall = Figure::new("map", "e", "n")
        .equal_aspect()
        .size(600, 900)
        .layer(Layer::line(
            vec![(0.0, 0.0), (1.0, 50.0)],
            Stroke::default(),
        ));
    let ((x0, x1), (y0, y1)) = data_ranges(&tall).unwrap();
    let (pw, ph) = plot_area_px(600, 900);
    assert!(((x1 - x0) / (y1 - y0) - f64::from(pw) / f64::from(ph)).abs() < 1e-9);
    assert!(
        (y0 - -2.5).abs() < 1e-9 && (y1 - 52.5).abs() < 1e-9,
        "y keeps the 5 % margin"
    );
}

#[test]
fn ranges_fit_data_with_margin_or_follow_explicit_ranges() {
    let fig = Figure::new("t", "x", "y").layer(Layer::line(
        vec![(0.0, 10.0), (10.0, 20.0)],
        Stroke::default(),
    ));
    let ((x0, x1), (y0, y1)) = data_ranges(&fig).unwrap();
    assert!((x0 + 0.5).abs() < 1e-12 && (x1 - 10.5).abs() < 1e-12);
    assert!((y0 - 9.5).abs() < 1e-12 && (y1 - 20.5).abs() < 1e-12);

    let fixed = fig.clone().x_range(-1.0, 1.0).y_range(0.0, 5.0);
    assert_eq!(data_ranges(&fixed).unwrap(), ((-1.0, 1.0), (0.0, 5.0)));

    for bad in [
        (1.0, 1.0),
        (2.0, 1.0),
        (f64::NAN, 1.0),
        (0.0, f64::INFINITY),
    ] {
        let f = fig.clone().x_range(bad.0, bad.1);
        assert!(
            matches!(data_ranges(&f), Err(ReportError::Invalid { .. })),
            "{bad:?}"
        );
    }
}

#[test]
fn identical_points_get_a_minimum_span() {
    let dir = Scratch::new("identical");
    for v in [0.0, 5.0, -3e6, 1e-9] {
        let fig = Figure::new("one point", "x", "y")
            .layer(Layer::points(vec![(v, v); 3], Rgb::RED, 3))
            .layer(Layer::line(vec![(v, v), (v, v)], Stroke::default()));
        let ((x0, x1), (y0, y1)) = data_ranges(&fig).unwrap();
        assert!(x0 < v && v < x1 && y0 < v && v < y1, "{v}");
        let [_, png] = write_figure(&fig, dir.path(), "same").unwrap();
        assert_eq!(png_size(&png), (900, 700));
    }
}

#[test]
fn non_finite_and_empty_layers_do_not_panic() {
    let dir = Scratch::new("non_finite");
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let fig = Figure::new("awkward", "x", "y")
        .layer(Layer::line(Vec::new(), Stroke::default()).with_label("empty line"))
        .layer(Layer::line(vec![(0.0, 0.0)], Stroke::default()))
        .layer(Layer::line(
            vec![(0.0, 0.0), (nan, 1.0), (1.0, inf), (2.0, 2.0), (3.0, 1.0)],
            Stroke::dashed(Rgb::BLUE, 3),
        ))
        .layer(Layer::points(
            vec![(nan, nan), (inf, 0.0), (1.0, 1.0)],
            Rgb::RED,
            4,
        ))
        .layer(Layer::points(Vec::new(), Rgb::RED, 0))
        .layer(Layer::points(vec![(0.5, 0.5)], Rgb::RED, u32::MAX))
        .layer(Layer::line(
            vec![(0.0, 1.0), (1.0, 0.0)],
            Stroke::dashed(Rgb::GREEN, u32::MAX),
        ))
        .layer(
            Layer::arrow((0.0, 2.0), (1.0, 0.0), Stroke::solid(Rgb::GREEN, u32::MAX))
                .with_label("fat"),
        )
        .layer(Layer::circle(
            (nan, 0.0),
            1.0,
            Some(Rgb::GREY),
            Stroke::default(),
        ))
        .layer(Layer::circle((0.0, 0.0), nan, None, Stroke::default()))
        .layer(Layer::circle((0.0, 0.0), -1.0, None, Stroke::default()))
        .layer(Layer::polygon(
            vec![(0.0, 0.0), (nan, 1.0)],
            Some(Rgb::GREEN),
            Stroke::default(),
        ))
        .layer(Layer::polygon(Vec::new(), None, Stroke::default()).with_label("empty polygon"))
        .layer(Layer::arrow((0.0, 0.0), (0.0, 0.0), Stroke::default()))
        .layer(Layer::arrow((nan, 0.0), (1.0, 1.0), Stroke::default()))
        .layer(Layer::arrow(
            (0.0, 0.0),
            (-inf, 1.0),
            Stroke::solid(Rgb::BLACK, 0),
        ))
        .layer(Layer::text((nan, 0.0), "lost", Rgb::BLACK))
        .layer(Layer::text((1.0, 1.0), "ctrl\u{0}chars\n<&>", Rgb::BLACK));
    let [svg, png] = write_figure(&fig, dir.path(), "awkward").unwrap();
    let text = read_svg(&svg);
    assert!(text.contains("empty line") && text.contains("empty polygon"));
    assert!(!text.contains('\u{0}'));
    assert_eq!(png_size(&png), (900, 700));

    let empty = Figure::new("Nothing yet", "x", "y");
    let [svg, _] = write_figure(&empty, dir.path(), "empty").unwrap();
    assert!(read_svg(&svg).contains("Nothing yet"));
    let only_nan = Figure::new("NaN only", "x", "y")
        .layer(Layer::line(vec![(nan, nan); 4], Stroke::default()));
    assert_eq!(data_ranges(&only_nan).unwrap(), ((0.0, 1.0), (0.0, 1.0)));
    write_figure(&only_nan, dir.path(), "nan").unwrap();
}

#[test]
fn geometry_far_outside_explicit_ranges_is_clipped() {
    let dir = Scratch::new("clipped");
    let fig = Figure::new("zoomed", "x", "y")
        .x_range(0.0, 1.0)
        .y_range(0.0, 1.0)
        .layer(Layer::line(
            vec![(-1e250, 0.5), (1e250, 0.5)],
            Stroke::dashed(Rgb::BLUE, 5),
        ))
        .layer(Layer::circle(
            (0.5, 0.5),
            1e200,
            Some(Rgb::GREY),
            Stroke::solid(Rgb::BLACK, 3),
        ))
        .layer(Layer::polygon(
            vec![(-1e300, -1e300), (1e300, -1e300), (0.0, 1e300)],
            Some(Rgb::GREEN),
            Stroke::default(),
        ))
        .layer(Layer::arrow(
            (-1e300, 0.0),
            (0.5, 0.5),
            Stroke::solid(Rgb::RED, 4),
        ))
        .layer(Layer::points(vec![(1e300, 1e300)], Rgb::RED, 5));
    let [_, png] = write_figure(&fig, dir.path(), "zoom").unwrap();
    assert_eq!(png_size(&png), (900, 700));
}

#[test]
fn extreme_magnitudes_render_or_fail_cleanly() {
    let dir = Scratch::new("extremes");
    let cases: &[&[(f64, f64)]] = &[
        &[(1e-300, 1e-300), (2e-300, 3e-300)],
        &[(1e15, 1e15), (1e15 + 1.0, 1e15 + 0.5)],
        &[(-1e12, 0.0), (1e12, 1e-12)],
        &[(1e299, -1e299), (1e299, 1e299)],
        &[(f64::MAX, 0.0), (-f64::MAX, 1.0)],
        &[(f64::MIN_POSITIVE, 0.0), (-0.0, 0.0)],
    ];
    for (i, pts) in cases.iter().enumerate() {
        let fig = Figure::new(format!("case {i}"), "x", "y")
            .layer(Layer::line(pts.to_vec(), Stroke::default()))
            .layer(Layer::points(pts.to_vec(), Rgb::BLUE, 3));
        match write_figure(&fig, dir.path(), &format!("case{i}")) {
            Ok([_, png]) => assert_eq!(png_size(&png), (900, 700)),
            Err(ReportError::Invalid { what }) => assert!(what.contains("range"), "{what}"),
            Err(e) => panic!("case {i}: unexpected error {e}"),
        }
        let _ = write_figure(&fig.clone().equal_aspect(), dir.path(), &format!("eq{i}"));
    }
}

#[test]
fn errors_name_the_path_at_fault() {
    let dir = Scratch::new("errors");
    let missing = dir.path().join("does-not-exist");
    let fig = sample_figure();
    match write_figure(&fig, &missing, "x") {
        Err(ReportError::Io { path, .. }) => assert_eq!(path, missing.join("x.svg")),
        other => panic!("expected Io error, got {other:?}"),
    }
    let err = write_figure(&fig, &missing, "x").unwrap_err().to_string();
    assert!(err.contains("does-not-exist"), "{err}");
    for stem in ["", "a/b", "..", "a\\b"] {
        assert!(matches!(
            write_figure(&fig, dir.path(), stem),
            Err(ReportError::Invalid { .. })
        ));
    }
    for (w, h) in [(0, 700), (900, 10), (100_000, 700)] {
        assert!(matches!(
            write_figure(&fig.clone().size(w, h), dir.path(), "s"),
            Err(ReportError::Invalid { .. })
        ));
    }
}

#[test]
fn heatmap_writes_files_with_colour_bar() {
    let dir = Scratch::new("heatmap");
    let xs: Vec<f64> = (0..21).map(|i| -1.0 + f64::from(i) * 0.1).collect();
    let ys: Vec<f64> = (0..11).map(|i| f64::from(i) * 0.2).collect();
    let z: Vec<Vec<f64>> = ys
        .iter()
        .map(|y| xs.iter().map(|x| x * y).collect())
        .collect();
    let mut map = Heatmap::new("Control surface", "e [m]", "psi [rad]", xs, ys, z)
        .z_label("steer [rad]")
        .layer(
            Layer::line(vec![(-1.0, 0.0), (1.0, 2.0)], Stroke::solid(Rgb::RED, 2))
                .with_label("path"),
        );
    map.z[3][4] = f64::NAN;
    assert_eq!(map.z_range().unwrap(), (-2.0, 2.0));
    let [svg, png] = write_heatmap(&map, dir.path(), "surface").unwrap();
    let text = read_svg(&svg);
    assert!(
        text.contains("Control surface") && text.contains("steer [rad]") && text.contains("path")
    );
    assert_eq!(png_size(&png), (900, 700));

    let eq = map.clone().equal_aspect().size(700, 700);
    let [_, png] = write_heatmap(&eq, dir.path(), "surface_eq").unwrap();
    assert_eq!(png_size(&png), (700, 700));

    let constant = Heatmap::new("flat", "x", "y", vec![0.0], vec![0.0], vec![vec![3.0]]);
    write_heatmap(&constant, dir.path(), "flat").unwrap();
    let all_nan = Heatmap::new(
        "nan",
        "x",
        "y",
        vec![0.0, 1.0],
        vec![0.0],
        vec![vec![f64::NAN; 2]],
    );
    write_heatmap(&all_nan, dir.path(), "nan").unwrap();
}

#[test]
fn heatmap_rejects_bad_grids() {
    let dir = Scratch::new("heatmap_bad");
    let bad = [
        Heatmap::new(
            "ragged",
            "x",
            "y",
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![vec![1.0, 2.0], vec![1.0]],
        ),
        Heatmap::new(
            "rows",
            "x",
            "y",
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![vec![1.0, 2.0]],
        ),
        Heatmap::new("empty", "x", "y", Vec::new(), Vec::new(), Vec::new()),
        Heatmap::new(
            "unsorted",
            "x",
            "y",
            vec![1.0, 0.0],
            vec![0.0],
            vec![vec![1.0, 2.0]],
        ),
        Heatmap::new(
            "nan axis",
            "x",
            "y",
            vec![0.0, f64::NAN],
            vec![0.0],
            vec![vec![1.0, 2.0]],
        ),
    ];
    for map in &bad {
        assert!(
            matches!(
                write_heatmap(map, dir.path(), "bad"),
                Err(ReportError::Invalid { .. })
            ),
            "{}",
            map.title
        );
    }
}
