//! A client that cannot use the service it finds says why, at once: another
//! protocol version, another program's service under the name, or none at
//! all. Each impostor service is made in this process with iceoryx2 itself,
//! as another build or program would make it.

use std::time::{Duration, Instant};

use gjkd_client::{Client, ConnectError};
use gjkd_e2e::unique_service;
use gjkd_proto::{PROTOCOL_VERSION, admin_service_name, query_service_name};
use iceoryx2::prelude::*;

/// Long enough that a test failing by waiting out the timeout would be
/// obvious in its message, not in a timed assertion.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(3);

fn node() -> Node<ipc::Service> {
    NodeBuilder::new()
        .create::<ipc::Service>()
        .expect("iceoryx2 node")
}

fn connect(service: &str) -> (Result<Client, ConnectError>, Duration) {
    let start = Instant::now();
    let result = Client::builder(service).timeout(CONNECT_TIMEOUT).connect();
    (result, start.elapsed())
}

#[test]
fn a_server_of_another_protocol_version_is_named() {
    let service = unique_service("other-version");
    let theirs = PROTOCOL_VERSION + 1;
    let node = node();
    let other_admin = admin_service_name(&service)
        .replace(&format!("/v{PROTOCOL_VERSION}/"), &format!("/v{theirs}/"));
    let _impostor = node
        .service_builder(&ServiceName::new(&other_admin).unwrap())
        .request_response::<u64, u64>()
        .create()
        .expect("other version's admin service");

    let (result, waited) = connect(&service);
    match result {
        Err(ConnectError::VersionMismatch {
            service: s,
            server,
            client,
        }) => {
            assert_eq!(s, service);
            assert_eq!(server, theirs);
            assert_eq!(client, PROTOCOL_VERSION);
        }
        other => panic!("expected VersionMismatch, got {:?}", other.map(|_| ())),
    }
    assert!(
        waited < CONNECT_TIMEOUT,
        "a version mismatch is final: the client must not wait for a server ({waited:?})"
    );
}

#[test]
fn a_server_of_an_older_protocol_version_is_named() {
    // What a client of this version meets on a host still running the
    // release before it (the first typed protocol replaced version 1).
    let service = unique_service("older-version");
    let theirs = PROTOCOL_VERSION - 1;
    let node = node();
    let old_admin = admin_service_name(&service)
        .replace(&format!("/v{PROTOCOL_VERSION}/"), &format!("/v{theirs}/"));
    let _old = node
        .service_builder(&ServiceName::new(&old_admin).unwrap())
        .request_response::<u64, u64>()
        .create()
        .expect("older version's admin service");

    let (result, waited) = connect(&service);
    match result {
        Err(ConnectError::VersionMismatch { server, client, .. }) => {
            assert_eq!((server, client), (theirs, PROTOCOL_VERSION));
        }
        other => panic!("expected VersionMismatch, got {:?}", other.map(|_| ())),
    }
    assert!(
        waited < CONNECT_TIMEOUT,
        "a version mismatch is final ({waited:?})"
    );
}

#[test]
fn a_service_with_other_message_types_is_incompatible() {
    let service = unique_service("other-types");
    let node = node();
    let query = query_service_name(&service);
    let _impostor = node
        .service_builder(&ServiceName::new(&query).unwrap())
        .request_response::<u64, u64>()
        .create()
        .expect("impostor query service");

    match connect(&service).0 {
        Err(ConnectError::Incompatible { service: s, cause }) => {
            assert_eq!(s, query);
            assert!(cause.contains("message types"), "cause: {cause}");
        }
        other => panic!("expected Incompatible, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn a_service_of_another_pattern_is_incompatible() {
    let service = unique_service("other-pattern");
    let node = node();
    let query = query_service_name(&service);
    let _impostor = node
        .service_builder(&ServiceName::new(&query).unwrap())
        .publish_subscribe::<u64>()
        .create()
        .expect("impostor publish-subscribe service");

    match connect(&service).0 {
        Err(ConnectError::Incompatible { service: s, cause }) => {
            assert_eq!(s, query);
            assert!(cause.contains("publish-subscribe"), "cause: {cause}");
        }
        other => panic!("expected Incompatible, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn no_service_at_all_is_a_server_gone() {
    let service = unique_service("nobody");
    let start = Instant::now();
    let result = Client::builder(&service)
        .timeout(Duration::from_millis(200))
        .connect();
    match result {
        Err(ConnectError::ServerGone(s)) => assert_eq!(s, service),
        other => panic!("expected ServerGone, got {:?}", other.map(|_| ())),
    }
    assert!(
        start.elapsed() >= Duration::from_millis(200),
        "a missing server is waited for until the connect timeout"
    );
}

#[test]
fn a_server_half_set_up_is_waited_for_not_called_incompatible() {
    // A starting server has made its query service but not yet its admin
    // service: the client must wait for it, not blame the name's owner.
    let service = unique_service("half-up");
    let node = node();
    let _query = node
        .service_builder(&ServiceName::new(&query_service_name(&service)).unwrap())
        .request_response::<[gjkd_proto::Item], [gjkd_proto::ReplyEntry]>()
        .response_user_header::<gjkd_proto::ReplyHeader>()
        .create()
        .expect("gjkd's own query service");
    let result = Client::builder(&service)
        .timeout(Duration::from_millis(200))
        .connect();
    match result {
        Err(ConnectError::ServerGone(s)) => assert_eq!(s, service),
        other => panic!("expected ServerGone, got {:?}", other.map(|_| ())),
    }
}
