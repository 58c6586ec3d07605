//! Pair gradients in batches through a real server: only the items that
//! ask carry one, the `k`-th into the caller's `gradients[k]`, against the
//! closed form of a one-joint arm (a 1 m rod turning about z, a ball
//! beside it: the gap closes at 0.8 m per radian) and of a free box (its
//! pose's twist); calls without room for a gradient refuse an item that
//! asks before sending anything.

use std::time::Duration;

use gjkd_client::{
    ErrorCode, Gradient, Item, ItemResult, ObjectId, PackagePath, QueryError, QueryOptions,
};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

const URDF: &str = r#"<robot name="arm"><link name="base"/>
  <link name="rod"><collision><origin xyz="0.5 0 0"/>
    <geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="rod"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

#[test]
fn batches_carry_the_gradients_asked_in_item_order() {
    let server = Server::start("gradient-batches", &["--no-persist"]);
    let mut client = server.client(Duration::from_secs(5));
    let identity = Isometry3::identity();
    let arm = client
        .register_robot_text("arm", URDF, None, None, &PackagePath::default(), &identity)
        .expect("arm");
    let rod = arm.link("rod").expect("the rod has geometry");
    let ball = client.register_sphere(0.1).expect("ball");
    client
        .set_pose(ball, &Isometry3::translation(0.8, 0.5, 0.0))
        .expect("pose");
    // A free box 2 below the ball's centre along -y (faces 0.5 from its
    // centre): 1.4 apart; moving the box up (+y) closes the gap.
    let cube = client
        .register_cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .expect("box");
    client
        .set_pose(cube, &Isometry3::translation(0.8, -1.5, 0.0))
        .expect("pose");
    let o = QueryOptions::cold();
    let ghost = ObjectId::from_raw(7);
    let items = [
        Item::distance(rod, ball, &o),
        Item::distance(rod, ball, &o).with_gradient(false),
        Item::distance(rod, ghost, &o).with_gradient(false),
        Item::distance(cube, ball, &o),
        Item::distance(cube, ball, &o).with_gradient(false),
        Item::distance(rod, ball, &o).with_gradient(true),
    ];
    let mut results = [ItemResult::default(); 6];
    let mut gradients = [Gradient::NONE; 5];
    // Rewritten by the call: stale values must not survive.
    gradients[1].columns = 9;
    let written = client
        .query_batch_gradients(&items, &mut results, &mut gradients)
        .expect("batch");
    assert_eq!(written, 4);
    let d = |k: usize| results[k].answer().expect("answered").distance;
    assert!((d(0) - 0.35).abs() < 1e-9 && d(1) == d(0) && d(5) == d(0));
    assert!((d(3) - 1.4).abs() < 1e-9 && d(4) == d(3));
    assert_eq!(results[2].error_code(), ErrorCode::UnknownObject);
    // The rod's joint: -0.8 per radian.
    assert_eq!(gradients[0].as_slice().len(), 1);
    assert!((gradients[0].as_slice()[0] + 0.8).abs() < 1e-9);
    assert!(!gradients[0].is_not_unique());
    // The failed item's gradient is empty.
    assert_eq!(gradients[1], Gradient::NONE);
    // The box's twist [v, ω]: moving it up closes the gap one for one;
    // turning it about its centre moves its top face's nearest point
    // along x or z, never towards the ball.
    let twist = gradients[2].as_slice();
    assert_eq!(twist.len(), 6);
    let want = [0.0, -1.0, 0.0, 0.0, 0.0, 0.0];
    for (got, want) in twist.iter().zip(want) {
        assert!((got - want).abs() < 1e-9, "{twist:?}");
    }
    // With the base: the joint, then the base twist's 6 columns.
    assert!(gradients[3].has_base());
    assert_eq!(gradients[3].as_slice().len(), 7);
    assert_eq!(gradients[3].as_slice()[0], gradients[0].as_slice()[0]);
    // The slot past the gradients asked is left alone.
    assert_eq!(gradients[4], Gradient::NONE);
    // The single-pair call joins its gradient into the answer.
    let answer = client
        .distance_gradient(rod, ball, &o, false)
        .expect("single");
    assert_eq!(answer.gradient, Some(gradients[0]));
    // The same reply read in place: the rows name their items.
    let mut seen = Vec::new();
    client
        .query_batch_read_gradients(&items, |r, rows| {
            assert_eq!(r.len(), items.len());
            seen.extend(rows.iter().map(|row| (row.item, row.gradient)));
        })
        .expect("read");
    let want: Vec<_> = [1, 2, 4, 5]
        .into_iter()
        .zip(gradients[..4].iter().copied())
        .collect();
    assert_eq!(seen, want);
}

#[test]
fn calls_without_room_for_a_gradient_refuse_before_sending() {
    let server = Server::start("gradient-refusals", &["--no-persist"]);
    let mut client = server.client(Duration::from_secs(5));
    let a = client.register_sphere(0.5).expect("a");
    let b = client.register_sphere(0.5).expect("b");
    let far = Isometry3::translation(3.0, 0.0, 0.0);
    let o = QueryOptions::default();
    // A pose update before the item that asks: refused whole, it must not
    // move anything.
    let items = [
        Item::set_pose(b, &far),
        Item::distance(a, b, &o).with_gradient(false),
    ];
    let before = client.stats().expect("stats").items;
    let mut results = [ItemResult::default(); 2];
    for outcome in [
        client.query_batch(&items, &mut results),
        client.query_batch_read(&items, |_| panic!("nothing to read")),
        client
            .query_batch_gradients(&items, &mut results, &mut [])
            .map(|_| ()),
    ] {
        assert!(outcome == Err(QueryError::NoRoomForGradient), "{outcome:?}");
    }
    assert_eq!(client.stats().expect("stats").items, before, "nothing sent");
    assert_eq!(results, [ItemResult::default(); 2], "nothing written");
    let d = client.distance(a, b, &o).expect("distance").distance;
    assert!(d.abs() < 1e-12, "b was not moved: {d}");
}
