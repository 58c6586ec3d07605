//! Bad input: every constructor and query error, and poses that would
//! overflow.

use super::*;

#[test]
fn constructor_errors() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let ok = p(0., 0., 0.);
    assert_eq!(
        no_panic("empty", || Convex::new(Vec::<P>::new(), 0.0)),
        Err(Error::EmptyVertices)
    );
    assert_eq!(
        no_panic("NaN vertex", || Convex::new(
            vec![ok, ok, p(0., nan, 0.)],
            0.0
        )),
        Err(Error::NonFiniteVertex(2))
    );
    assert_eq!(
        no_panic("inf vertex", || Convex::new(vec![p(inf, 0., 0.), ok], 0.0)),
        Err(Error::NonFiniteVertex(0))
    );
    assert_eq!(
        no_panic("-inf vertex", || Convex::new(
            vec![ok, p(0., 0., -inf)],
            0.0
        )),
        Err(Error::NonFiniteVertex(1))
    );
    // Finite vertices whose spread overflows.
    assert!(matches!(
        no_panic("overflowing spread", || Convex::new(
            vec![p(-1.7e308, 0., 0.), p(1.7e308, 0., 0.)],
            0.0
        )),
        Err(Error::NonFiniteVertex(_))
    ));
    assert_eq!(
        no_panic("negative radius", || Convex::sphere(-1.0)),
        Err(Error::InvalidRadius(-1.0))
    );
    assert!(matches!(
        no_panic("NaN radius", || Convex::new(vec![ok], nan)),
        Err(Error::InvalidRadius(r)) if r.is_nan()
    ));
    assert_eq!(
        no_panic("inf radius", || Convex::new(vec![ok], inf)),
        Err(Error::InvalidRadius(inf))
    );
    assert_eq!(
        no_panic("NaN capsule", || Convex::capsule(ok, p(nan, 0., 0.), 1.0)),
        Err(Error::NonFiniteVertex(1))
    );
    assert!(matches!(
        no_panic("negative half extent", || Convex::cuboid(
            v(1., -1., 1.),
            0.0
        )),
        Err(Error::NonFiniteVertex(_))
    ));
    assert!(matches!(
        no_panic("NaN half extent", || Convex::cuboid(v(1., 1., nan), 0.0)),
        Err(Error::NonFiniteVertex(_))
    ));
    assert!(matches!(
        no_panic("cuboid bad radius", || Convex::cuboid(v(1., 1., 1.), -0.5)),
        Err(Error::InvalidRadius(_))
    ));
    // Zero is a valid radius and a valid half extent.
    assert!(Convex::sphere(0.0).is_ok());
    assert!(Convex::cuboid(v(0., 0., 0.), 0.0).is_ok());
    assert_eq!(
        no_panic("empty compound", || Compound::<Convex>::new(vec![])),
        Err(Error::EmptyCompound)
    );
    let piece = Convex::sphere(1.0).unwrap();
    assert_eq!(
        no_panic("NaN offset", || Compound::new(vec![(
            iso(0., nan, 0.),
            piece.clone()
        )])),
        Err(Error::NonFinitePose)
    );
    assert_eq!(
        no_panic("inf offset", || Compound::new(vec![
            (Isometry3::identity(), piece.clone()),
            (iso(inf, 0., 0.), piece.clone())
        ])),
        Err(Error::NonFinitePose)
    );
    // WarmStart holds at most four pairs.
    assert!(WarmStart::new([0, 0], &[[0, 0]; 5]).is_none());
    assert_eq!(
        WarmStart::new([0, 0], &[[1, 2], [3, 4]]).unwrap().pairs(),
        &[[1, 2], [3, 4]]
    );
}

#[test]
fn query_errors() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let b: Shape = Convex::capsule(p(0., 0., 0.), p(0., 0., 1.), 0.1)
        .unwrap()
        .into();
    let o = Isometry3::identity();
    let far = iso(5., 0., 0.);
    let run = |pa: &Isometry3<f64>, pb: &Isometry3<f64>, opt: &Options, w: Option<&WarmStart>| {
        no_panic("query", || distance(&a, pa, &b, pb, opt, w))
    };
    let d = Options::default();
    // Poses.
    assert_eq!(
        run(&iso(nan, 0., 0.), &far, &d, None),
        Err(Error::NonFinitePose)
    );
    assert_eq!(
        run(&o, &iso(0., 0., -inf), &d, None),
        Err(Error::NonFinitePose)
    );
    let bad_rot = Isometry3::from_parts(
        Translation3::new(0., 0., 0.),
        Unit::new_unchecked(Quaternion::new(nan, 0., 0., 0.)),
    );
    assert_eq!(run(&o, &bad_rot, &d, None), Err(Error::NonFinitePose));
    // Options.
    for tolerance in [nan, -1e-3, inf] {
        let opt = Options { tolerance, ..d };
        assert!(
            matches!(run(&o, &far, &opt, None), Err(Error::InvalidOption(_))),
            "tolerance {tolerance}"
        );
    }
    let opt = Options {
        max_iterations: 0,
        ..d
    };
    assert!(matches!(
        run(&o, &far, &opt, None),
        Err(Error::InvalidOption(_))
    ));
    for m in [nan, inf, -inf] {
        let opt = Options {
            margin: Some(m),
            ..d
        };
        assert!(
            matches!(run(&o, &far, &opt, None), Err(Error::InvalidOption(_))),
            "margin {m}"
        );
    }
    // Edge values that are valid.
    assert!(
        run(
            &o,
            &far,
            &Options {
                tolerance: 0.0,
                ..d
            },
            None
        )
        .is_ok()
    );
    assert!(
        run(
            &o,
            &far,
            &Options {
                max_iterations: 1,
                ..d
            },
            None
        )
        .is_ok()
    );
    assert!(
        run(
            &o,
            &far,
            &Options {
                margin: Some(-1.0),
                ..d
            },
            None
        )
        .is_ok()
    );
    // Warm start indices: A has 8 vertices, B has 2; one piece each.
    let w = |pieces, pairs: &[[u32; 2]]| WarmStart::new(pieces, pairs).unwrap();
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[8, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[0, 0], [7, 2]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([1, 0], &[[0, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 1], &[[0, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[u32::MAX, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    // In range: the right answer (box face at x = 1, capsule axis at x = 5).
    let ans = run(&o, &far, &d, Some(&w([0, 0], &[[7, 1], [0, 0]]))).unwrap();
    assert!((ans.distance - 3.9).abs() < 1e-14, "{ans:?}");
    // An empty warm start is the cold start.
    let ans = run(&o, &far, &d, Some(&w([0, 0], &[]))).unwrap();
    assert!((ans.distance - 3.9).abs() < 1e-14, "{ans:?}");
}

#[test]
fn compound_warm_start_out_of_range() {
    let piece = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap();
    let c: Shape = Compound::new(vec![
        (iso(-2., 0., 0.), piece.clone()),
        (iso(2., 0., 0.), piece),
    ])
    .unwrap()
    .into();
    let s: Shape = Convex::sphere(1.0).unwrap().into();
    let o = Isometry3::identity();
    let far = iso(0., 5., 0.);
    let d = Options::default();
    for (pieces, pairs) in [
        ([2, 0], [[0, 0]]),
        ([0, 1], [[0, 0]]),
        ([1, 0], [[8, 0]]),
        ([1, 0], [[0, 1]]),
    ] {
        let w = WarmStart::new(pieces, &pairs).unwrap();
        assert_eq!(
            no_panic("compound warm", || distance(&c, &o, &s, &far, &d, Some(&w))),
            Err(Error::WarmStartOutOfRange),
            "pieces {pieces:?} pairs {pairs:?}"
        );
    }
    let w = WarmStart::new([1, 0], &[[7, 0]]).unwrap();
    let ans = distance(&c, &o, &s, &far, &d, Some(&w)).unwrap();
    // Nearest point of piece 1 ([1, 3] × [-1, 1]²) to (0, 5, 0) is (1, 1, 0).
    assert!(
        (ans.distance - (17f64.sqrt() - 1.0)).abs() < 1e-14,
        "{ans:?}"
    );
    assert_eq!(ans.pieces, [1, 0]);
}

#[test]
fn overflowing_poses_are_an_error_not_a_panic() {
    // Finite inputs whose relative pose overflows f64.
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let pa = iso(-1.7e308, 0., 0.);
    let pb = iso(1.7e308, 0., 0.);
    let got = no_panic("poses at ±1.7e308", || {
        distance(&a, &pa, &a, &pb, &Options::default(), None)
    });
    assert_eq!(got, Err(Error::NonFinitePose));
}
