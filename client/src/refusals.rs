//! How an operation's error is tied to the wire: which of its variants is
//! which [`ErrorCode`], how it reads as the umbrella [`ClientError`], and
//! how the plumbing every call shares (which speaks [`ClientError`]) hands
//! its failures to the operation's own error.

use gjkd_proto::ErrorCode;

use crate::{ClientError, ConnectError};

/// An operation's error: the server's refusals it can meet, and its
/// connection faults.
pub(crate) trait Operation: From<ConnectError> {
    /// The variant of a refusal with `code`, `None` for a code the server
    /// never gives this operation.
    fn refused(code: ErrorCode) -> Option<Self>;
}

/// The error of operation `E` for a failure of the shared plumbing (a
/// refusal or a connection fault). A code the server never gives this
/// operation means a server this client does not understand: a protocol
/// fault, as any other answer out of the protocol.
pub(crate) fn op_error<E: Operation>(e: ClientError) -> E {
    match e {
        ClientError::Rejected(code) => E::refused(code).unwrap_or_else(|| {
            E::from(ConnectError::Protocol(format!(
                "the server refused the call with `{code}`, which it never answers it with"
            )))
        }),
        other => E::from(ConnectError::from_client(other)),
    }
}

/// Writes, for an operation's error `$error`: which of its unit variants
/// is a refusal with which code (`Variant` for the code of the same name,
/// `Variant = Code` otherwise), the conversion into [`ClientError`] (a
/// refusal becomes [`ClientError::Rejected`], the other variants as the
/// arms after `others` say), `code()` (the refusal's code, else the code
/// of the same fault in [`ClientError`], so the two never differ) and
/// [`Operation`]. One table, so the code of a variant and the variant of
/// a code cannot drift apart.
macro_rules! refusals {
    (
        $error:ident {
            $($variant:ident $(= $code:ident)?),* $(,)?
        }
        others { $($pat:pat => $into:expr),* $(,)? }
    ) => {
        impl $error {
            /// The [`ErrorCode`] of this fault: the server's for a
            /// refusal, and for a fault this client finds before sending
            /// the code the server gives the same fault; `None` for a fault
            /// no code names (a server gone, a timeout, an argument that
            /// cannot be sent). The same code as
            /// [`ClientError::code`](crate::ClientError::code) of the
            /// fault converted, so Rust, Python and C report one fault with
            /// one code (`docs/errors.md`).
            pub fn code(&self) -> Option<gjkd_proto::ErrorCode> {
                match self {
                    $($error::$variant => Some(refusals!(@code $variant $($code)?)),)*
                    other => $crate::ClientError::from(other.clone()).code(),
                }
            }
        }

        impl From<$error> for $crate::ClientError {
            /// The same fault in the error every call can convert into: a
            /// refusal as [`ClientError::Rejected`](crate::ClientError::Rejected)
            /// with its code.
            fn from(e: $error) -> Self {
                match e {
                    $($error::$variant => {
                        $crate::ClientError::Rejected(refusals!(@code $variant $($code)?))
                    })*
                    $($pat => $into,)*
                }
            }
        }

        impl $crate::refusals::Operation for $error {
            fn refused(code: gjkd_proto::ErrorCode) -> Option<Self> {
                match code {
                    $(refusals!(@pattern $variant $($code)?) => Some($error::$variant),)*
                    _ => None,
                }
            }
        }
    };
    (@code $variant:ident) => { gjkd_proto::ErrorCode::$variant };
    (@code $variant:ident $code:ident) => { gjkd_proto::ErrorCode::$code };
    (@pattern $variant:ident) => { gjkd_proto::ErrorCode::$variant };
    (@pattern $variant:ident $code:ident) => { gjkd_proto::ErrorCode::$code };
}

pub(crate) use refusals;
