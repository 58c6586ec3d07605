//! The workload: the settings compared, the family's queries, and the
//! brute-force references they are judged by.

#[allow(unused_imports)]
use super::*;

/// A query with its reference.
pub(crate) struct Query {
    pub(crate) family: String,
    pub(crate) label: String,
    pub(crate) a: usize,
    pub(crate) b: usize,
    pub(crate) pose_a: Isometry3<f64>,
    pub(crate) pose_b: Isometry3<f64>,
    /// Sum of the bounding radii about the body origins.
    pub(crate) size: f64,
    pub(crate) truth: f64,
    pub(crate) warm: Option<WarmStart>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Group {
    TolCold,
    TolWarm,
    Cap,
    Margin,
    Precision,
}

impl Group {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Group::TolCold => "tolerance, cold",
            Group::TolWarm => "tolerance, warm",
            Group::Cap => "iteration cap, cold",
            Group::Margin => "early-exit margin",
            Group::Precision => "f32 support search",
        }
    }
}

pub(crate) struct Setting {
    pub(crate) name: String,
    pub(crate) group: Group,
    pub(crate) options: Options,
    /// Margin as a fraction of each pair's size.
    pub(crate) margin: Option<f64>,
}

pub(crate) fn settings() -> Vec<Setting> {
    let mut out = Vec::new();
    let tols = [
        1e-15,
        1e-14,
        DEFAULT_EPS,
        1e-13,
        1e-12,
        1e-10,
        1e-8,
        1e-6,
        1e-4,
        1e-3,
        1e-2,
    ];
    for (group, warm) in [(Group::TolCold, false), (Group::TolWarm, true)] {
        for &t in &tols {
            let tag = if t == DEFAULT_EPS {
                "ε=2.2e-14 (default)".to_owned()
            } else {
                format!("ε={t:.0e}")
            };
            out.push(Setting {
                name: format!("{tag} {}", if warm { "warm" } else { "cold" }),
                group,
                options: Options {
                    tolerance: t,
                    warm_start: warm,
                    ..Options::default()
                },
                margin: None,
            });
        }
    }
    for cap in [1u32, 2, 3, 4, 6, 8, 12] {
        out.push(Setting {
            name: format!("cap {cap} cold"),
            group: Group::Cap,
            options: Options {
                max_iterations: cap,
                warm_start: false,
                ..Options::default()
            },
            margin: None,
        });
    }
    for warm in [false, true] {
        out.push(Setting {
            name: format!("f32 support {}", if warm { "warm" } else { "cold" }),
            group: Group::Precision,
            options: Options {
                precision: Precision::Single,
                warm_start: warm,
                ..Options::default()
            },
            margin: None,
        });
    }
    for (f, warm) in [(0.01, false), (0.1, false), (1.0, false), (0.1, true)] {
        out.push(Setting {
            name: format!("margin {f}·size {}", if warm { "warm" } else { "cold" }),
            group: Group::Margin,
            options: Options {
                warm_start: warm,
                ..Options::default()
            },
            margin: Some(f),
        });
    }
    out
}

pub(crate) fn bounding(s: &Shape) -> f64 {
    let convex = |c: &gjk::Convex, off: &Isometry3<f64>| {
        c.vertices()
            .iter()
            .map(|v| (off * v).coords.norm())
            .fold(0.0, f64::max)
            + c.radius()
    };
    match s {
        Shape::Convex(c) => convex(c, &Isometry3::identity()),
        Shape::Compound(c) => c
            .pieces()
            .iter()
            .map(|(o, p)| convex(p, o))
            .fold(0.0, f64::max),
    }
}

pub(crate) fn scaled(c: &gjk::Convex, s: f64) -> gjk::Convex {
    let v: Vec<Point3<f64>> = c.vertices().iter().map(|p| p * s).collect();
    gjk::Convex::new(v, c.radius() * s).expect("scaled vertices are finite")
}

/// The workload: shapes and queries (references not yet known).
pub(crate) fn workload(per_pair: usize) -> (Vec<Shape>, Vec<(extremes::RawCase, usize, usize)>) {
    let family = paper::family();
    let mut shapes: Vec<Shape> = family.iter().cloned().map(Shape::from).collect();
    let mut raw = Vec::new();
    for case in Case::ALL {
        for c in paper::cases(case, per_pair, 7) {
            raw.push((
                extremes::RawCase {
                    family: match case {
                        Case::Separated => "§7 separated",
                        Case::Touching => "§7 touching",
                        Case::Intersecting => "§7 intersecting",
                    },
                    label: format!("pair {} (M={})", c.pair + 1, c.m),
                    a: shapes[c.a].clone(),
                    pose_a: c.pose_a,
                    b: shapes[c.b].clone(),
                    pose_b: c.pose_b,
                    analytic: None,
                },
                c.a,
                c.b,
            ));
        }
    }
    // The paper's separated cases at tiny and huge scales.
    for (scale, name) in [(1e-6, "tiny scale"), (1e6, "huge scale")] {
        let base = shapes.len();
        shapes.extend(family.iter().map(|c| Shape::from(scaled(c, scale))));
        for c in paper::cases(Case::Separated, 1, 11) {
            let sc = |p: &Isometry3<f64>| {
                Isometry3::from_parts(Translation3::from(p.translation.vector * scale), p.rotation)
            };
            raw.push((
                extremes::RawCase {
                    family: name,
                    label: format!("§7 pair {} scaled by {scale:e}", c.pair + 1),
                    a: shapes[base + c.a].clone(),
                    pose_a: sc(&c.pose_a),
                    b: shapes[base + c.b].clone(),
                    pose_b: sc(&c.pose_b),
                    analytic: None,
                },
                base + c.a,
                base + c.b,
            ));
        }
    }
    for e in extremes::cases() {
        let (ia, ib) = (shapes.len(), shapes.len() + 1);
        shapes.push(e.a.clone());
        shapes.push(e.b.clone());
        raw.push((e, ia, ib));
    }
    (shapes, raw)
}

pub(crate) fn points_of(s: &Shape) -> (Vec<Point3<f64>>, f64) {
    match s {
        Shape::Convex(c) => (c.vertices().to_vec(), c.radius()),
        Shape::Compound(_) => unreachable!("the bench families are convex"),
    }
}

/// A hash of everything a reference depends on, so a cache from other
/// inputs (another family version, another `--per-pair`) is never used.
pub(crate) fn inputs_hash(raw: &[(extremes::RawCase, usize, usize)]) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    // The reference method's version: a cache from another method is stale.
    h.write_u32(3);
    for (r, _, _) in raw {
        for s in [&r.a, &r.b] {
            let (pts, rad) = points_of(s);
            for p in pts {
                for c in p.coords.iter() {
                    h.write_u64(c.to_bits());
                }
            }
            h.write_u64(rad.to_bits());
        }
        for p in [&r.pose_a, &r.pose_b] {
            for c in p.translation.vector.iter().chain(p.rotation.coords.iter()) {
                h.write_u64(c.to_bits());
            }
        }
    }
    h.finish()
}

/// References for `raw`, from the cache when it holds these very inputs.
pub(crate) fn references(
    raw: &[(extremes::RawCase, usize, usize)],
    shapes: &[Shape],
    cache_dir: &Path,
    progress: &Progress,
) -> Result<Vec<f64>, BenchError> {
    let hash = inputs_hash(raw);
    let path = cache_dir.join(format!("reference-{hash:016x}.csv"));
    if let Ok(text) = std::fs::read_to_string(&path) {
        let vals: Vec<f64> = text
            .lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(1))
            .filter_map(|hex| u64::from_str_radix(hex, 16).ok())
            .map(f64::from_bits)
            .collect();
        if vals.len() == raw.len() {
            progress.println(format!("reference distances: cached in {}", path.display()));
            return Ok(vals);
        }
    }
    let t0 = Instant::now();
    let mut hulls: BTreeMap<usize, (Hull, f64)> = BTreeMap::new();
    let mut out = Vec::with_capacity(raw.len());
    for (i, (r, ia, ib)) in raw.iter().enumerate() {
        if i % 50 == 0 {
            progress.step(format!("exact reference distances: {i}/{}", raw.len()));
        }
        if let Some(d) = r.analytic {
            out.push(d);
            continue;
        }
        for &k in [ia, ib] {
            hulls.entry(k).or_insert_with(|| {
                let (pts, rad) = points_of(&shapes[k]);
                (Hull::new(&pts), rad)
            });
        }
        let (ha, ra) = &hulls[ia];
        let (hb, rb) = &hulls[ib];
        let truth = reference::distance(ha, &r.pose_a, *ra, hb, &r.pose_b, *rb);
        // Cores not proven apart are within round-off of contact, where the
        // reference may answer a round-off-sized distance: they count as
        // touching, so that "per distance" errors stay those of separated
        // queries.
        out.push(if truth.separated { truth.distance } else { 0.0 });
    }
    let mut csv = Csv::new(&["index", "distance_bits", "distance", "family", "label"]);
    for ((r, _, _), d) in raw.iter().zip(&out) {
        csv.row(&[
            String::new(),
            format!("{:016x}", d.to_bits()),
            format!("{d:e}"),
            r.family.to_owned(),
            r.label.clone(),
        ]);
    }
    io("create the cache dir", std::fs::create_dir_all(cache_dir))?;
    io("write the reference cache", csv.write(&path))?;
    progress.println(format!(
        "reference distances: computed in {:.1} s, cached in {}",
        t0.elapsed().as_secs_f64(),
        path.display()
    ));
    Ok(out)
}

/// The pose one small step before `pose`: 1% of `size` along a fixed
/// direction and 0.02 rad about a fixed axis.
pub(crate) fn step_back(pose: &Isometry3<f64>, size: f64) -> Isometry3<f64> {
    let dir = Vector3::new(0.6, -0.48, 0.64);
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.9, -0.3).normalize() * 0.02);
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector - dir * (0.01 * size)),
        rot * pose.rotation,
    )
}
