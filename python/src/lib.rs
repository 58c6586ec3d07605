//! The native module of the `gjkd` Python package (`gjkd._native`): the
//! client of a gjkd server, the in-process store (`Local`), shapes, the
//! batch results on numpy arrays, and the server command. The package's
//! Python files (`gjkd/`) add the exceptions, the enums and `gjkd.Server`.

mod api;
mod arrays;
mod backend;
mod batch;
mod client;
mod errors;
mod local;
mod local_calls;
mod meshes;
mod robot_api;
mod robots;
mod runner;
mod scene;
mod scene_api;
mod server_lib;
mod shape;
mod thread;

use pyo3::prelude::*;

/// Runs `gjkd serve` with these arguments (without the program name, e.g.
/// `["--service", "mine", "--wait", "spin"]`) until SIGINT or SIGTERM;
/// returns the exit status. The GIL is released while serving.
#[pyfunction]
fn serve(py: Python<'_>, args: Vec<String>) -> i32 {
    py.detach(move || server_lib::serve(&args))
}

/// Every error code as `(name, value, description)`, in wire order.
#[pyfunction]
fn error_codes() -> Vec<(String, u32, &'static str)> {
    gjkd_proto::ErrorCode::ALL
        .iter()
        .map(|c| (format!("{c:?}"), c.raw(), c.describe()))
        .collect()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // iceoryx2 logs to the console by itself; keep it to real problems, as
    // the `gjkd` binary does.
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    m.add_class::<client::Client>()?;
    m.add_class::<local::Local>()?;
    m.add_class::<shape::Shape>()?;
    m.add_class::<robots::Robot>()?;
    m.add_class::<batch::Distances>()?;
    m.add_class::<batch::Answer>()?;
    m.add_class::<scene::SceneRows>()?;
    m.add_class::<scene::Summary>()?;
    m.add_class::<meshes::MeshInfo>()?;
    m.add_function(wrap_pyfunction!(serve, m)?)?;
    m.add_function(wrap_pyfunction!(error_codes, m)?)?;
    m.add_function(wrap_pyfunction!(thread::pin_thread, m)?)?;
    m.add_function(wrap_pyfunction!(thread::set_realtime_priority, m)?)?;
    m.add("DEFAULT_TOLERANCE", gjkd_proto::DEFAULT_TOLERANCE)?;
    m.add("DEFAULT_MAX_ITERATIONS", gjkd_proto::DEFAULT_MAX_ITERATIONS)?;
    m.add("MAX_PIECES", gjkd_proto::MAX_PIECES)?;
    m.add("MAX_NAME_LEN", gjkd_proto::MAX_NAME_LEN)?;
    m.add("PROTOCOL_VERSION", gjkd_proto::PROTOCOL_VERSION)?;
    Ok(())
}
