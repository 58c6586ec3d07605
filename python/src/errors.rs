//! Python exceptions raised by the native module. The hierarchy itself is
//! defined in Python (`gjkd/_errors.py`), where each class can also derive
//! from the matching built-in (`ConnectionError`, `TimeoutError`,
//! `ValueError`, `LookupError`); this file only builds instances of it.

use gjkd_client::{ClientError, ErrorCode};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// Which Python class an error is raised as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `gjkd.ServerGone`.
    ServerGone,
    /// `gjkd.Timeout`.
    Timeout,
    /// `gjkd.InvalidInput`.
    InvalidInput,
    /// `gjkd.NotFound`.
    NotFound,
    /// `gjkd.Refused`.
    Refused,
    /// `gjkd.ProtocolError`.
    Protocol,
    /// `gjkd.IpcError`.
    Ipc,
    /// `gjkd.Incompatible`.
    Incompatible,
    /// `gjkd.AccessDenied`.
    AccessDenied,
    /// `gjkd.Error` itself.
    Other,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::ServerGone => "ServerGone",
            Kind::Timeout => "Timeout",
            Kind::InvalidInput => "InvalidInput",
            Kind::NotFound => "NotFound",
            Kind::Refused => "Refused",
            Kind::Protocol => "ProtocolError",
            Kind::Ipc => "IpcError",
            Kind::Incompatible => "Incompatible",
            Kind::AccessDenied => "AccessDenied",
            Kind::Other => "Error",
        }
    }

    /// The class a refusal with `code` is raised as.
    pub fn of_code(code: ErrorCode) -> Kind {
        use ErrorCode as E;
        match code {
            E::UnknownObject | E::UnknownName => Kind::NotFound,
            E::NotOwner
            | E::ReadOnly
            | E::NameTaken
            | E::TooManyObjects
            | E::Internal
            | E::StorageFull => Kind::Refused,
            E::Ok => Kind::Other,
            _ => Kind::InvalidInput,
        }
    }
}

/// The argument a refusal with `code` most likely concerns, for calls that
/// do not know better.
pub fn field_of(code: ErrorCode) -> Option<&'static str> {
    use ErrorCode as E;
    Some(match code {
        E::EmptyVertices | E::TooManyVertices | E::NonFiniteVertex => "vertices",
        E::InvalidRadius => "radius",
        E::NonFinitePose | E::BadQuaternion => "pose",
        E::EmptyCompound | E::TooManyPieces => "pieces",
        E::NameTaken | E::UnknownName => "name",
        E::UnknownObject | E::NotOwner | E::ReadOnly => "id",
        _ => return None,
    })
}

/// An exception of class `kind` with its attributes.
pub struct Raise<'a> {
    /// Class.
    pub kind: Kind,
    /// Message.
    pub message: String,
    /// Error code, if the error has one.
    pub code: Option<ErrorCode>,
    /// The argument at fault.
    pub field: Option<&'a str>,
    /// The row of the argument at fault.
    pub index: Option<usize>,
}

impl Raise<'_> {
    /// The Python exception.
    pub fn into_err(self, py: Python<'_>) -> PyErr {
        match self.build(py) {
            Ok(err) => err,
            Err(err) => err,
        }
    }

    fn build(self, py: Python<'_>) -> PyResult<PyErr> {
        let module = py.import("gjkd._errors")?;
        let class = module.getattr(self.kind.class_name())?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("code", self.code.map(|c| c.raw()))?;
        kwargs.set_item("field", self.field.map(|f| PyString::new(py, f)))?;
        kwargs.set_item("index", self.index)?;
        let value = class.call((self.message,), Some(&kwargs))?;
        Ok(PyErr::from_value(value))
    }
}

/// `gjkd.InvalidInput` about `field` (row `index`), without a server code.
pub fn invalid(py: Python<'_>, field: &str, index: Option<usize>, message: String) -> PyErr {
    Raise {
        kind: Kind::InvalidInput,
        message,
        code: None,
        field: Some(field),
        index,
    }
    .into_err(py)
}

/// The exception of a refusal with `code`, about `field` (default: the
/// code's usual argument) at row `index`.
pub fn refused(
    py: Python<'_>,
    code: ErrorCode,
    field: Option<&str>,
    index: Option<usize>,
) -> PyErr {
    let field = field.or_else(|| field_of(code));
    let message = match (field, index) {
        (Some(f), Some(i)) => format!("{code} ({f}, row {i})"),
        (Some(f), None) => format!("{code} ({f})"),
        _ => code.to_string(),
    };
    Raise {
        kind: Kind::of_code(code),
        message,
        code: Some(code),
        field,
        index,
    }
    .into_err(py)
}

/// The exception of a failed client call: any operation's error
/// (`RegisterError`, `QueryError`, ...), read through the umbrella
/// [`ClientError`], so that one fault is one class with one `code`
/// whichever call met it.
pub fn client(py: Python<'_>, e: impl Into<ClientError>, field: Option<&str>) -> PyErr {
    let e: ClientError = e.into();
    let (kind, code) = match &e {
        ClientError::ServerGone(_) => (Kind::ServerGone, None),
        ClientError::Timeout(_) => (Kind::Timeout, None),
        ClientError::Rejected(code) => return refused(py, *code, field, None),
        ClientError::InvalidArgument(_) | ClientError::InvalidMesh(_) => (Kind::InvalidInput, None),
        // Faults the client finds before sending carry the code the server
        // gives them, as in Rust (`ClientError::code`) and C.
        ClientError::InvalidRobot(_) => (Kind::InvalidInput, e.code()),
        ClientError::UnknownJoint(_) => (Kind::NotFound, e.code()),
        ClientError::Protocol(_) => (Kind::Protocol, None),
        ClientError::Ipc(_) => (Kind::Ipc, None),
        ClientError::VersionMismatch { .. } | ClientError::Incompatible { .. } => {
            (Kind::Incompatible, None)
        }
        ClientError::PermissionDenied(_) => (Kind::AccessDenied, None),
        ClientError::TooManyClients(_) => (Kind::Refused, None),
        ClientError::ResultBufferTooSmall { .. } => (Kind::Other, None),
    };
    Raise {
        kind,
        message: e.to_string(),
        code,
        field: if kind == Kind::InvalidInput || code.is_some() {
            field
        } else {
            None
        },
        index: None,
    }
    .into_err(py)
}
