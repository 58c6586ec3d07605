//! Mesh files and URDF the tests write themselves.

#![allow(dead_code)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A fresh scratch folder for one test.
pub fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gjkd-model-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The 8 corners of the box `[-h, h]` and its 12 outward triangles.
pub fn cuboid(h: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..8 {
        let s = |bit: u32| if i >> bit & 1 == 1 { 1.0 } else { -1.0 };
        v.push([s(0) * h[0], s(1) * h[1], s(2) * h[2]]);
    }
    // Corner index = x + 2y + 4z (bits); faces wound outwards.
    let t = vec![
        [0, 2, 3],
        [0, 3, 1], // z-
        [4, 5, 7],
        [4, 7, 6], // z+
        [0, 1, 5],
        [0, 5, 4], // y-
        [2, 6, 7],
        [2, 7, 3], // y+
        [0, 4, 6],
        [0, 6, 2], // x-
        [1, 3, 7],
        [1, 7, 5], // x+
    ];
    (v, t)
}

/// An octahedron with half axes `h` and its 8 triangles.
pub fn octahedron(h: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let v = vec![
        [h[0], 0.0, 0.0],
        [-h[0], 0.0, 0.0],
        [0.0, h[1], 0.0],
        [0.0, -h[1], 0.0],
        [0.0, 0.0, h[2]],
        [0.0, 0.0, -h[2]],
    ];
    let t = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (v, t)
}

fn normal(v: &[[f64; 3]], t: [u32; 3]) -> [f32; 3] {
    let [a, b, c] = t.map(|i| v[i as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    n.map(|c| (c / l) as f32)
}

/// Binary STL.
pub fn write_stl_binary(path: &Path, v: &[[f64; 3]], t: &[[u32; 3]]) {
    let mut out = vec![0u8; 80];
    out.extend((t.len() as u32).to_le_bytes());
    for &tri in t {
        for c in normal(v, tri) {
            out.extend(c.to_le_bytes());
        }
        for i in tri {
            for c in v[i as usize] {
                out.extend((c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    std::fs::write(path, out).unwrap();
}

/// ASCII STL.
pub fn write_stl_ascii(path: &Path, v: &[[f64; 3]], t: &[[u32; 3]]) {
    let mut s = String::from("solid test\n");
    for &tri in t {
        let n = normal(v, tri);
        writeln!(s, "facet normal {} {} {}\n outer loop", n[0], n[1], n[2]).unwrap();
        for i in tri {
            let p = v[i as usize];
            writeln!(s, "  vertex {} {} {}", p[0], p[1], p[2]).unwrap();
        }
        s.push_str(" endloop\nendfacet\n");
    }
    s.push_str("endsolid test\n");
    std::fs::write(path, s).unwrap();
}

/// Wavefront OBJ.
pub fn write_obj(path: &Path, v: &[[f64; 3]], t: &[[u32; 3]]) {
    let mut s = String::from("# test\no thing\n");
    for p in v {
        writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for f in t {
        writeln!(s, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    std::fs::write(path, s).unwrap();
}

/// COLLADA 1.4 with one mesh geometry instanced at the root, in units of
/// `meter` metres.
pub fn write_dae(path: &Path, v: &[[f64; 3]], t: &[[u32; 3]], meter: f64) {
    let floats: Vec<String> = v.iter().flatten().map(|c| c.to_string()).collect();
    let indices: Vec<String> = t.iter().flatten().map(|i| i.to_string()).collect();
    let s = format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="unit" meter="{meter}"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="thing-mesh" name="thing">
      <mesh>
        <source id="thing-positions">
          <float_array id="thing-positions-array" count="{fc}">{floats}</float_array>
          <technique_common>
            <accessor source="#thing-positions-array" count="{vc}" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="thing-vertices"><input semantic="POSITION" source="#thing-positions"/></vertices>
        <triangles count="{tc}">
          <input semantic="VERTEX" source="#thing-vertices" offset="0"/>
          <p>{indices}</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="thing" name="thing" type="NODE">
        <instance_geometry url="#thing-mesh" name="thing"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"##,
        fc = floats.len(),
        floats = floats.join(" "),
        vc = v.len(),
        tc = t.len(),
        indices = indices.join(" "),
    );
    std::fs::write(path, s).unwrap();
}

/// The test arm: 8 links (box, sphere, four meshes in four formats, two
/// box fingers), 7 joints (revolute, prismatic, continuous, fixed, and a
/// mimic), mesh paths relative and `package://`.
pub const ARM_URDF: &str = r#"<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <collision><geometry><box size="0.4 0.4 0.2"/></geometry></collision>
  </link>
  <link name="shoulder">
    <collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="upper">
    <collision><geometry><mesh filename="meshes/upper.stl"/></geometry></collision>
  </link>
  <link name="slider">
    <collision><geometry><mesh filename="package://arm_meshes/slider_ascii.stl" scale="2 1 1"/></geometry></collision>
  </link>
  <link name="wrist">
    <collision><geometry><mesh filename="meshes/wrist.obj"/></geometry></collision>
  </link>
  <link name="hand">
    <collision><origin xyz="0 0 0.02" rpy="0 0 0.5"/><geometry><mesh filename="meshes/hand.dae"/></geometry></collision>
    <collision><origin xyz="0 0 -0.02"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <link name="finger_l">
    <collision><geometry><box size="0.01 0.01 0.04"/></geometry></collision>
  </link>
  <link name="finger_r">
    <collision><geometry><box size="0.01 0.01 0.04"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="shoulder"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="shoulder"/><child link="upper"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="j3" type="prismatic">
    <parent link="upper"/><child link="slider"/>
    <origin xyz="0.3 0 0" rpy="0.1 0.2 0.3"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/>
  </joint>
  <joint name="j4" type="continuous">
    <parent link="slider"/><child link="wrist"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="j5" type="fixed">
    <parent link="wrist"/><child link="hand"/>
    <origin xyz="0 0 0.05" rpy="0 1.5707963267948966 0"/>
  </joint>
  <joint name="j6" type="revolute">
    <parent link="hand"/><child link="finger_l"/>
    <origin xyz="0 0.02 0"/><axis xyz="0 1 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j7" type="revolute">
    <parent link="hand"/><child link="finger_r"/>
    <origin xyz="0 -0.02 0"/><axis xyz="0 -1 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="j6" multiplier="-1" offset="0.1"/>
  </joint>
</robot>
"#;

/// The arm's mesh files: `dir/meshes/{upper.stl (binary), wrist.obj,
/// hand.dae}` and `dir/pkg/arm_meshes/slider_ascii.stl`. Returns the URDF's
/// path (`dir/arm.urdf`) and the package folder (`dir/pkg`).
pub fn write_arm(dir: &Path) -> (PathBuf, PathBuf) {
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::create_dir_all(dir.join("pkg/arm_meshes")).unwrap();
    let (v, t) = cuboid([0.15, 0.03, 0.03]);
    write_stl_binary(&dir.join("meshes/upper.stl"), &v, &t);
    let (v, t) = octahedron([0.05, 0.03, 0.02]);
    write_stl_ascii(&dir.join("pkg/arm_meshes/slider_ascii.stl"), &v, &t);
    let (v, t) = cuboid([0.02, 0.02, 0.02]);
    write_obj(&dir.join("meshes/wrist.obj"), &v, &t);
    // Millimetres, to check the COLLADA unit is applied.
    let (v, t) = cuboid([30.0, 20.0, 10.0]);
    write_dae(&dir.join("meshes/hand.dae"), &v, &t, 0.001);
    let urdf = dir.join("arm.urdf");
    std::fs::write(&urdf, ARM_URDF).unwrap();
    (urdf, dir.join("pkg"))
}

/// A small deterministic generator (xorshift), so that failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    /// A number in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The folder holding the vendored real robots (example-robot-data's
/// panda and UR5): the package search path their `package://` URLs need.
pub fn real_robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// The vendored panda's URDF (example-robot-data's, Franka's arm and hand).
pub fn panda_urdf() -> PathBuf {
    real_robots().join("example-robot-data/robots/panda_description/urdf/panda.urdf")
}

/// The vendored UR5's URDF (example-robot-data's, from ros-industrial).
pub fn ur5_urdf() -> PathBuf {
    real_robots().join("example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
}
