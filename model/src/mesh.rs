//! Triangle meshes: loaded from binary or ASCII STL, OBJ and COLLADA files
//! (with the `mesh-loader` crate) or given as arrays; their convex hull, or a
//! convex decomposition (parry3d-f64's V-HACD).
//!
//! GJK needs nothing but a convex set's vertices, so a mesh goes to gjk as
//! its hull's vertices: the hull contains the mesh, so a distance to it is
//! never more than the distance to the mesh itself (and equal wherever the
//! closest points lie on the mesh's convex parts). A decomposition is closer
//! to a non-convex mesh, at the price of several pieces.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use gjk::{Compound, Convex};
use nalgebra::{Isometry3, Point3};
use parry3d_f64::math::Vector;

use crate::collada;

/// What can go wrong with a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be read (missing, unreadable).
    #[error("cannot read mesh file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file was read but is not a mesh of a known format (STL, OBJ,
    /// COLLADA, told apart by extension and content).
    #[error("cannot parse mesh file {path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// The mesh has no vertices.
    #[error("mesh {0} has no vertices")]
    Empty(String),
    /// A vertex or scale factor is NaN or infinite, or a scale factor zero.
    #[error("mesh {what}: {reason}")]
    NotFinite {
        /// The file or "arrays".
        what: String,
        /// What is not finite.
        reason: String,
    },
    /// A triangle names a vertex the mesh does not have.
    #[error("triangle {triangle} names vertex {index}, but the mesh has {count}")]
    BadIndex {
        /// The triangle.
        triangle: usize,
        /// The index.
        index: u32,
        /// Vertices in the mesh.
        count: usize,
    },
    /// The convex decomposition found no pieces (a mesh with no volume, no
    /// triangles, or a resolution too coarse).
    #[error("the convex decomposition found no pieces (does the mesh enclose a volume?)")]
    NoPieces,
    /// gjk refused the resulting shape (too many vertices, too large).
    #[error("mesh is not a valid shape: {0}")]
    Shape(#[from] gjk::Error),
}

/// A triangle mesh in double precision.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertices.
    pub vertices: Vec<Point3<f64>>,
    /// Triangles, as indices into `vertices` (may be empty: a point cloud).
    pub triangles: Vec<[u32; 3]>,
}

/// A convex decomposition of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    /// Each piece's hull vertices, in the mesh's frame.
    pub pieces: Vec<Vec<Point3<f64>>>,
    /// The largest distance found from a point of the pieces' hulls outside
    /// the mesh to the mesh's surface: how much farther out the pieces reach
    /// than the mesh, so how much less distance they may report. Measured at
    /// the hulls' vertices, edge midpoints and face centroids, so a lower
    /// estimate of the true largest deviation.
    pub deviation: f64,
}

impl Mesh {
    /// Reads a mesh file (binary or ASCII STL, OBJ, COLLADA `.dae`) and
    /// scales it by `scale` (per axis); all the file's meshes are merged,
    /// COLLADA's unit and node transforms applied (see `collada.rs`: the
    /// geometries its scene places, each by its nodes' transforms composed
    /// parent first; the up axis is ignored, as in ROS). Coordinates are read in
    /// single precision (binary STL's own; the `mesh-loader` crate reads
    /// OBJ and COLLADA text that way too), then widened and scaled.
    ///
    /// # Errors
    /// [`MeshError::Io`], [`MeshError::Parse`], [`MeshError::Empty`],
    /// [`MeshError::NotFinite`].
    pub fn load(path: &Path, scale: [f64; 3]) -> Result<Mesh, MeshError> {
        let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let is_collada = is_collada(path, &bytes);
        let flat = is_collada
            .then(|| {
                std::str::from_utf8(&bytes)
                    .ok()
                    .and_then(collada::flatten_scene)
            })
            .flatten();
        let (bytes, placements) = match flat {
            Some(flat) => (flat.text.into_bytes(), flat.placements),
            None => (bytes, HashMap::new()),
        };
        // One mesh per geometry, named by its id, for its placement.
        let loader = mesh_loader::Loader::default().merge_meshes(false);
        let named = lower_case_extension(path);
        let scene = loader
            .load_from_slice(&bytes, &named)
            .or_else(|e| match binary_stl_named_solid(&bytes) {
                Some(binary) => loader.load_from_slice(&binary, &named),
                None => Err(e),
            })
            .map_err(|e| MeshError::Parse {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let mut mesh = Mesh::default();
        for m in &scene.meshes {
            let base = u32::try_from(mesh.vertices.len()).unwrap_or(u32::MAX);
            let place = placements.get(&m.name);
            mesh.vertices.extend(m.vertices.iter().map(|v| {
                let p = Point3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
                let p = place.map_or(p, |t| t.transform_point(&p));
                Point3::new(p.x * scale[0], p.y * scale[1], p.z * scale[2])
            }));
            mesh.triangles.extend(
                m.faces
                    .iter()
                    .map(|f| [f[0] + base, f[1] + base, f[2] + base]),
            );
        }
        let what = path.display().to_string();
        check_scale(&what, scale)?;
        mesh.check(&what)?;
        Ok(mesh)
    }

    /// A mesh of these vertices and triangles.
    ///
    /// # Errors
    /// [`MeshError::Empty`], [`MeshError::NotFinite`], [`MeshError::BadIndex`].
    pub fn from_arrays(
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Mesh, MeshError> {
        let mesh = Mesh {
            vertices,
            triangles,
        };
        mesh.check("arrays")?;
        Ok(mesh)
    }

    fn check(&self, what: &str) -> Result<(), MeshError> {
        if self.vertices.is_empty() {
            return Err(MeshError::Empty(what.to_owned()));
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.coords.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NotFinite {
                what: what.to_owned(),
                reason: format!("vertex {i} is not finite"),
            });
        }
        let count = self.vertices.len();
        for (triangle, t) in self.triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= count) {
                return Err(MeshError::BadIndex {
                    triangle,
                    index,
                    count,
                });
            }
        }
        Ok(())
    }

    /// The mesh scaled per axis.
    ///
    /// # Errors
    /// [`MeshError::NotFinite`] for a NaN, infinite or zero factor.
    pub fn scaled(mut self, scale: [f64; 3]) -> Result<Mesh, MeshError> {
        check_scale("scale", scale)?;
        for v in &mut self.vertices {
            for (c, s) in v.coords.iter_mut().zip(scale) {
                *c *= s;
            }
        }
        Ok(self)
    }

    /// The vertices of the mesh's convex hull. A flat or degenerate mesh
    /// (no volume) keeps all its vertices, duplicates removed: their convex
    /// set is what gjk takes anyway.
    pub fn hull(&self) -> Vec<Point3<f64>> {
        let points: Vec<Vector> = self
            .vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        match parry3d_f64::transformation::try_convex_hull(&points) {
            Ok((hull, _)) if hull.len() >= 4 => {
                hull.iter().map(|v| Point3::new(v.x, v.y, v.z)).collect()
            }
            _ => {
                let mut unique = self.vertices.clone();
                unique.sort_by(|a, b| {
                    a.coords
                        .as_slice()
                        .partial_cmp(b.coords.as_slice())
                        .unwrap_or(std::cmp::Ordering::Equal)
                });
                unique.dedup();
                unique
            }
        }
    }

    /// The hull as a gjk shape.
    ///
    /// # Errors
    /// [`MeshError::Shape`] when gjk refuses it.
    pub fn to_convex(&self) -> Result<Convex, MeshError> {
        Ok(Convex::new(self.hull(), 0.0)?)
    }

    /// A convex decomposition by V-HACD at `resolution` voxels along the
    /// longest side (parry's default is 64; higher is finer and slower).
    ///
    /// # Errors
    /// [`MeshError::NoPieces`] when V-HACD finds none (no triangles, no
    /// volume).
    pub fn decompose(&self, resolution: u32) -> Result<Decomposition, MeshError> {
        use parry3d_f64::transformation::vhacd::{VHACD, VHACDParameters};
        if self.triangles.is_empty() {
            return Err(MeshError::NoPieces);
        }
        let points: Vec<Vector> = self
            .vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        let params = VHACDParameters {
            resolution: resolution.max(8),
            ..VHACDParameters::default()
        };
        let vhacd = VHACD::decompose(&params, &points, &self.triangles, true);
        let hulls = vhacd.compute_exact_convex_hulls(&points, &self.triangles);
        let hulls: Vec<(Vec<Vector>, Vec<[u32; 3]>)> =
            hulls.into_iter().filter(|(v, _)| !v.is_empty()).collect();
        if hulls.is_empty() {
            return Err(MeshError::NoPieces);
        }
        let deviation = self.largest_deviation(&hulls);
        let pieces = hulls
            .into_iter()
            .map(|(v, _)| v.iter().map(|p| Point3::new(p.x, p.y, p.z)).collect())
            .collect();
        Ok(Decomposition { pieces, deviation })
    }

    fn largest_deviation(&self, hulls: &[(Vec<Vector>, Vec<[u32; 3]>)]) -> f64 {
        use parry3d_f64::query::PointQuery;
        use parry3d_f64::shape::{TriMesh, TriMeshFlags};
        let points: Vec<Vector> = self
            .vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        let Ok(mesh) = TriMesh::with_flags(
            points,
            self.triangles.clone(),
            TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES,
        ) else {
            return f64::NAN;
        };
        let mut worst: f64 = 0.0;
        let mut probe = |p: Vector| {
            let projection = mesh.project_local_point(p, true);
            if !projection.is_inside {
                worst = worst.max((projection.point - p).length());
            }
        };
        for (vertices, faces) in hulls {
            for f in faces {
                let [a, b, c] = f.map(|i| vertices[i as usize]);
                for p in [a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5] {
                    probe(p);
                }
                probe((a + b + c) / 3.0);
            }
        }
        worst
    }
}

impl Decomposition {
    /// The pieces as one gjk compound (each piece at the identity offset).
    ///
    /// # Errors
    /// [`MeshError::Shape`] when gjk refuses it (for example more pieces than
    /// a compound may have).
    pub fn to_compound(&self) -> Result<Compound, MeshError> {
        let pieces = self
            .pieces
            .iter()
            .map(|p| Ok((Isometry3::identity(), Convex::new(p.clone(), 0.0)?)))
            .collect::<Result<Vec<_>, gjk::Error>>()?;
        Ok(Compound::new(pieces)?)
    }
}

/// `path` with its extension in lower case: `mesh-loader` tells a format
/// by its extension in lower or upper case only, and exporters also write
/// `.Stl` or `.Obj` (binary STL and OBJ have no marker to tell them by
/// otherwise).
fn lower_case_extension(path: &Path) -> std::borrow::Cow<'_, Path> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.chars().any(|c| c.is_ascii_uppercase()) => {
            path.with_extension(e.to_ascii_lowercase()).into()
        }
        _ => path.into(),
    }
}

/// Whether `mesh-loader` reads `bytes` (from `path`) as COLLADA: by the
/// `.dae` extension, or, with no extension it knows, by `<COLLADA` among
/// the first kilobyte, as the crate tells formats apart.
fn is_collada(path: &Path, bytes: &[u8]) -> bool {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("dae") => true,
        Some("stl" | "obj") => false,
        _ => bytes[..bytes.len().min(1024)]
            .windows(8)
            .any(|w| w == b"<COLLADA"),
    }
}

/// Binary STL's header: free text, then the triangle count.
const STL_HEADER: usize = 80;
/// One binary STL triangle: normal, three vertices, attribute count.
const STL_TRIANGLE: usize = 50;

/// The bytes of a binary STL file whose header begins with `solid` (as
/// some exporters write it), with that header blanked; `None` for anything
/// else. `mesh-loader` takes such a file for ASCII STL and fails on its
/// first triangle; the header is free text, so blanking it changes no
/// triangle. Binary is recognised by its size: exactly the header, the
/// count and the count's triangles, which ASCII text beginning with
/// `solid` does not match by chance.
fn binary_stl_named_solid(bytes: &[u8]) -> Option<Vec<u8>> {
    let header = bytes.get(..STL_HEADER)?;
    let count = u32::from_le_bytes(bytes.get(STL_HEADER..STL_HEADER + 4)?.try_into().ok()?);
    let size = (count as usize)
        .checked_mul(STL_TRIANGLE)?
        .checked_add(STL_HEADER + 4)?;
    let named_solid = header.trim_ascii_start().starts_with(b"solid");
    if !named_solid || size != bytes.len() {
        return None;
    }
    let mut binary = bytes.to_vec();
    binary[..STL_HEADER].fill(0);
    Some(binary)
}

fn check_scale(what: &str, scale: [f64; 3]) -> Result<(), MeshError> {
    if scale.iter().all(|s| s.is_finite() && *s != 0.0) {
        Ok(())
    } else {
        Err(MeshError::NotFinite {
            what: what.to_owned(),
            reason: format!("scale {scale:?} must be finite and non-zero"),
        })
    }
}
