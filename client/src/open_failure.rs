//! Why an iceoryx2 service could not be opened, sorted into what a caller
//! can act on: wait for a server, use another build, fix permissions.

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::EventOpenError;
use iceoryx2::service::builder::request_response::RequestResponseOpenError;
use iceoryx2::service::static_config::messaging_pattern::MessagingPattern;

/// The classes of open failure that lead to different [`ClientError`]s.
///
/// [`ClientError`]: crate::ClientError
pub(crate) enum OpenFailure {
    /// No such service, or one that is going away or not yet set up: a
    /// server may (re)appear.
    Missing,
    /// The service exists with other types, limits or iceoryx2 version.
    Incompatible(String),
    /// The service belongs to a user this process may not act as.
    Permission,
    /// The service admits no more nodes.
    Full,
    /// Anything else iceoryx2 reports (its own internal failures).
    Other(String),
}

impl From<RequestResponseOpenError> for OpenFailure {
    fn from(e: RequestResponseOpenError) -> Self {
        use RequestResponseOpenError as E;
        match e {
            E::DoesNotExist
            | E::IsMarkedForDestruction
            | E::HangsInCreation
            | E::ServiceInCorruptedState
            | E::Interrupt => OpenFailure::Missing,
            E::InsufficientPermissions => OpenFailure::Permission,
            E::ExceedsMaxNumberOfNodes => OpenFailure::Full,
            E::IncompatibleRequestOrResponseType => {
                OpenFailure::Incompatible("other message types (another build of gjkd?)".into())
            }
            E::IncompatibleMessagingPattern => OpenFailure::Incompatible(
                "not a request-response service (another program uses the name?)".into(),
            ),
            E::VersionMismatch => {
                OpenFailure::Incompatible("made by another iceoryx2 version".into())
            }
            E::InternalFailure | E::UnableToCreateServiceTag => {
                OpenFailure::Other(format!("{e:?}"))
            }
            other => OpenFailure::Incompatible(format!("other service settings: {other:?}")),
        }
    }
}

impl From<EventOpenError> for OpenFailure {
    fn from(e: EventOpenError) -> Self {
        use EventOpenError as E;
        match e {
            E::DoesNotExist
            | E::IsMarkedForDestruction
            | E::HangsInCreation
            | E::ServiceInCorruptedState
            | E::Interrupt => OpenFailure::Missing,
            E::InsufficientPermissions => OpenFailure::Permission,
            E::ExceedsMaxNumberOfNodes => OpenFailure::Full,
            E::IncompatibleMessagingPattern => OpenFailure::Incompatible(
                "not an event service (another program uses the name?)".into(),
            ),
            E::VersionMismatch => {
                OpenFailure::Incompatible("made by another iceoryx2 version".into())
            }
            E::InternalFailure | E::UnableToCreateServiceTag => {
                OpenFailure::Other(format!("{e:?}"))
            }
            other => OpenFailure::Incompatible(format!("other service settings: {other:?}")),
        }
    }
}

/// What a missing service's name is taken by instead, found by a scan of
/// the host's services. Only asked when our own version's service is
/// missing, so its cost is off every path that works.
pub(crate) enum NameTakenBy {
    /// A gjkd server of this protocol version.
    Version(u32),
    /// A service of another messaging pattern under one of our names
    /// (iceoryx2 tells services apart by name and pattern, so opening ours
    /// just finds nothing).
    OtherPattern {
        /// The service name.
        name: String,
        /// The pattern found there.
        pattern: String,
    },
}

/// Who holds `service`'s names (any protocol version) in a way that keeps
/// this client from using them, if anyone does. `ours` are our three names
/// with whether each is an event service (the others are request-response);
/// finding one of them with its own pattern is no obstacle: it is a server
/// still starting or going away.
pub(crate) fn name_taken_by(service: &str, ours: [(&str, bool); 3]) -> Option<NameTakenBy> {
    let prefix = format!("{service}/v");
    let mut found = None;
    let _ = ipc::Service::list(Config::global_config(), |details| {
        let config = &details.static_details;
        let name = config.name().as_str();
        let version = name
            .strip_prefix(&prefix)
            .and_then(|rest| rest.strip_suffix("/admin"))
            .and_then(|v| v.parse::<u32>().ok());
        found = match version {
            Some(v) if v != gjkd_proto::PROTOCOL_VERSION => Some(NameTakenBy::Version(v)),
            _ => ours
                .iter()
                .find(|(ours, _)| *ours == name)
                .filter(|(_, event)| !has_pattern(config.messaging_pattern(), *event))
                .map(|_| NameTakenBy::OtherPattern {
                    name: name.to_owned(),
                    pattern: pattern_name(config.messaging_pattern()).to_owned(),
                }),
        };
        if found.is_some() {
            CallbackProgression::Stop
        } else {
            CallbackProgression::Continue
        }
    });
    found
}

fn has_pattern(pattern: &MessagingPattern, event: bool) -> bool {
    if event {
        matches!(pattern, MessagingPattern::Event(_))
    } else {
        matches!(pattern, MessagingPattern::RequestResponse(_))
    }
}

fn pattern_name(pattern: &MessagingPattern) -> &'static str {
    match pattern {
        MessagingPattern::RequestResponse(_) => "request-response",
        MessagingPattern::PublishSubscribe(_) => "publish-subscribe",
        MessagingPattern::Event(_) => "event",
        _ => "differently patterned",
    }
}
