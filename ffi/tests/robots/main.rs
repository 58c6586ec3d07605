//! Meshes and robots through the C API, against a real server: a URDF arm
//! written here (box, sphere and STL mesh links; revolute, prismatic and
//! fixed joints), its link poses against transforms computed here by hand,
//! link distances against analytic answers, and every error path with its
//! status, code and message.
//!
//! One test binary, one file a concept: the shared arm (`arm.rs`), a robot
//! moving (`moves.rs`), poses read back (`poses.rs`), meshes (`meshes.rs`), their errors
//! (`mesh_errors.rs`, `robot_errors.rs`), cylinders (`cylinders.rs`).

// Robots and meshes are in the library with its `robots` feature only.
#![cfg(feature = "robots")]

mod arm;
mod cylinders;
mod mesh_errors;
mod meshes;
mod moves;
mod poses;
mod robot_errors;
