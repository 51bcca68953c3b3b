//! Compiling MJCF with MuJoCo's C library (cargo feature `mujoco`).
//!
//! Expected sizes, names and arrays of `ARM` were taken from the Python bindings of the
//! same library (PyPI mujoco==3.17.0, `mujoco.MjModel.from_xml_string`).
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo (a build without the feature has none of it).
#![cfg(mjcf_mujoco)]

use std::path::Path;
use std::sync::Arc;

use mjcf_forge::mujoco::{CompileError, CompiledModel, ObjType, Sizes, compile_file, compile_str};

const ARM: &str = r#"<mujoco model="arm">
  <compiler angle="radian"/>
  <default>
    <geom friction="0.8 0.01 0.001"/>
  </default>
  <asset>
    <texture name="grid" type="2d" builtin="checker" width="32" height="32" rgb1="0 0 0" rgb2="1 1 1"/>
    <material name="floor_mat" texture="grid"/>
  </asset>
  <worldbody>
    <light name="top" pos="0 0 3"/>
    <camera name="cam0" pos="0 -2 1"/>
    <geom name="floor" type="plane" size="2 2 0.1" material="floor_mat"/>
    <body name="upper" pos="0 0 1">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-1.5 1.5"/>
      <geom name="upper_geom" type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
      <site name="elbow_site" pos="0.5 0 0"/>
      <body name="lower" pos="0.5 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" range="-2 2"/>
        <geom name="lower_geom" type="box" size="0.2 0.05 0.05" pos="0.2 0 0"/>
      </body>
    </body>
    <body name="ball" pos="1 0 0.5">
      <freejoint name="ball_free"/>
      <geom name="ball_geom" type="sphere" size="0.1" friction="1 0.005 0.0001"/>
    </body>
    <body name="target" mocap="true" pos="0 0 2"/>
  </worldbody>
  <tendon>
    <fixed name="coupling">
      <joint joint="shoulder" coef="1"/>
      <joint joint="elbow" coef="-1"/>
    </fixed>
  </tendon>
  <equality>
    <joint name="couple_eq" joint1="shoulder" joint2="elbow" active="false"/>
  </equality>
  <actuator>
    <motor name="m_shoulder" joint="shoulder" gear="2"/>
    <position name="p_elbow" joint="elbow" kp="10"/>
  </actuator>
  <sensor>
    <jointpos name="s_elbow" joint="elbow"/>
    <framepos name="s_site" objtype="site" objname="elbow_site"/>
  </sensor>
  <keyframe>
    <key name="home" time="0"/>
  </keyframe>
</mujoco>
"#;

const TETRAHEDRON_OBJ: &str =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n\
f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

const MESH_MODEL: &str = r#"<mujoco model="meshy">
  <compiler meshdir="meshes"/>
  <asset>
    <mesh name="tet" file="tet.obj" scale="0.1 0.1 0.1"/>
  </asset>
  <worldbody>
    <body name="piece" pos="0 0 1">
      <freejoint/>
      <geom name="piece_geom" type="mesh" mesh="tet"/>
    </body>
  </worldbody>
</mujoco>
"#;

fn here() -> &'static Path {
    Path::new(".")
}

fn write_mesh_dir(obj: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("meshes")).unwrap();
    std::fs::write(dir.path().join("meshes/tet.obj"), obj).unwrap();
    dir
}

fn compile_err(xml: &str) -> CompileError {
    match compile_str(xml, here()) {
        Ok(model) => panic!("expected an error, compiled {:?}", model.sizes()),
        Err(err) => err,
    }
}

#[test]
fn valid_model_sizes_match_python() {
    let model = compile_str(ARM, here()).unwrap();
    let sizes = model.sizes();
    let expected = Sizes {
        nbody: 5,
        njnt: 3,
        ngeom: 4,
        nsite: 1,
        nu: 2,
        nsensor: 2,
        nq: 9,
        nv: 8,
        nmesh: 0,
        na: 0,
        nactuator: 2,
        ncam: 1,
        nlight: 1,
        ntex: 1,
        nmat: 1,
        ntendon: 1,
        nwrap: 2,
        neq: 1,
        nkey: 1,
        nmocap: 1,
        nsensordata: 4,
        nnames: 190,
        ..Sizes::default()
    };
    assert_eq!(sizes, expected);
    assert!(model.warnings().is_none(), "{:?}", model.warnings());
}

#[test]
fn sizes_json_has_stable_key_order() {
    let json = compile_str(ARM, here()).unwrap().sizes().to_json();
    assert!(
        json.starts_with(
            r#"{"nbody":5,"njnt":3,"ngeom":4,"nsite":1,"nu":2,"nsensor":2,"nq":9,"nv":8,"nmesh":0,"na":0,"nactuator":2,"#
        ),
        "{json}"
    );
    assert!(json.ends_with(r#""nnames":190}"#), "{json}");
    assert_eq!(json.matches(':').count(), Sizes::LEN);
}

#[test]
fn valid_model_names_match_python() {
    let model = compile_str(ARM, here()).unwrap();
    let expect: [(ObjType, &[&str]); 14] = [
        (
            ObjType::Body,
            &["world", "upper", "lower", "ball", "target"],
        ),
        (ObjType::Joint, &["shoulder", "elbow", "ball_free"]),
        (
            ObjType::Geom,
            &["floor", "upper_geom", "lower_geom", "ball_geom"],
        ),
        (ObjType::Site, &["elbow_site"]),
        (ObjType::Camera, &["cam0"]),
        (ObjType::Light, &["top"]),
        (ObjType::Mesh, &[]),
        (ObjType::Material, &["floor_mat"]),
        (ObjType::Texture, &["grid"]),
        (ObjType::Tendon, &["coupling"]),
        (ObjType::Actuator, &["m_shoulder", "p_elbow"]),
        (ObjType::Sensor, &["s_elbow", "s_site"]),
        (ObjType::Equality, &["couple_eq"]),
        (ObjType::Key, &["home"]),
    ];
    for (obj, names) in expect {
        assert_eq!(model.names(obj), names, "{obj}");
    }
}

#[test]
fn unnamed_objects_give_empty_names() {
    let xml = r#"<mujoco><worldbody><geom name="floor" type="plane" size="1 1 1"/>
        <geom size="0.1"/></worldbody></mujoco>"#;
    assert_eq!(
        compile_str(xml, here()).unwrap().names(ObjType::Geom),
        ["floor", ""]
    );
}

#[test]
fn valid_model_arrays_match_python() {
    let model = compile_str(ARM, here()).unwrap();
    assert_eq!(
        model.body_pos(),
        [
            0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 2.0
        ]
    );
    assert_eq!(model.body_quat(), [1.0, 0.0, 0.0, 0.0].repeat(5));
    assert_eq!(
        model.geom_size(),
        [
            2.0, 2.0, 0.1, 0.05, 0.25, 0.0, 0.2, 0.05, 0.05, 0.1, 0.0, 0.0
        ]
    );
    assert_eq!(
        model.geom_friction(),
        [
            0.8, 0.01, 0.001, 0.8, 0.01, 0.001, 0.8, 0.01, 0.001, 1.0, 0.005, 0.0001
        ]
    );
    assert_eq!(model.jnt_range(), [-1.5, 1.5, -2.0, 2.0, 0.0, 0.0]);
    let mut gainprm = vec![0.0; 20];
    gainprm[0] = 1.0;
    gainprm[10] = 10.0;
    assert_eq!(model.actuator_gainprm(), gainprm);
    assert_eq!(model.body_parentid(), [0, 0, 1, 0, 0]);
    assert_eq!(model.jnt_type(), [3, 3, 0]);
    assert_eq!(model.qpos0().len(), 9);
    assert_eq!(model.key_qpos().len(), 9);
    assert_eq!(model.geom_rgba().len(), 16);
}

#[test]
fn compile_file_resolves_assets_next_to_the_file() {
    let dir = write_mesh_dir(TETRAHEDRON_OBJ);
    let path = dir.path().join("mesh.xml");
    std::fs::write(&path, MESH_MODEL).unwrap();
    let model = compile_file(&path).unwrap();
    let s = model.sizes();
    // Python: nbody 2, njnt 1, ngeom 1, nmesh 1, nq 7, nv 6, nmeshvert 4.
    assert_eq!(
        (s.nbody, s.njnt, s.ngeom, s.nmesh, s.nq, s.nv),
        (2, 1, 1, 1, 7, 6)
    );
    assert_eq!(model.mesh_vertex_count(), 4);
    assert_eq!(model.names(ObjType::Mesh), ["tet"]);
    assert_eq!(model.body_pos()[3..], [0.0, 0.0, 1.0]);
}

#[test]
fn compile_str_resolves_assets_against_dir() {
    let tet = write_mesh_dir(TETRAHEDRON_OBJ);
    let cube = write_mesh_dir(CUBE_OBJ);
    let from_tet = compile_str(MESH_MODEL, tet.path()).unwrap();
    let from_cube = compile_str(MESH_MODEL, cube.path()).unwrap();
    assert_eq!(from_tet.mesh_vertex_count(), 4);
    assert_eq!(from_cube.mesh_vertex_count(), 8);
    // Nothing was written into the directory.
    let entries: Vec<_> = std::fs::read_dir(tet.path()).unwrap().collect();
    assert_eq!(entries.len(), 1);
}

#[test]
fn schema_error_carries_mujoco_text_and_line() {
    let xml = "<mujoco>\n  <worldbody>\n    <body name=\"b\">\n      <geom type=\"sphere\" size=\"0.1\"/>\n      <geom type=\"box\" sizee=\"1 1 1\"/>\n    </body>\n  </worldbody>\n</mujoco>\n";
    let err = compile_err(xml);
    assert!(
        err.message.contains("unrecognized attribute: 'sizee'"),
        "{err}"
    );
    assert!(err.message.contains("Element 'geom', line 5"), "{err}");
    assert_eq!(err.element_line, Some(5));
    assert_eq!(err.to_string(), err.message);
}

#[test]
fn compiler_error_carries_line() {
    let xml = "<mujoco>\n  <worldbody>\n    <body>\n      <joint name=\"j\"/>\n      <geom size=\"0.1\"/>\n    </body>\n  </worldbody>\n  <actuator>\n    <motor joint=\"nope\"/>\n  </actuator>\n</mujoco>\n";
    let err = compile_err(xml);
    assert!(
        err.message.contains("unknown transmission target 'nope'"),
        "{err}"
    );
    assert_eq!(err.element_line, Some(9));
}

#[test]
fn malformed_xml_carries_line() {
    let err = compile_err(
        "<mujoco>\n  <worldbody>\n    <geom size=\"0.1\">\n  </worldbody>\n</mujoco>\n",
    );
    assert!(err.message.contains("XML parse error"), "{err}");
    assert_eq!(err.element_line, Some(3));
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    for xml in [
        "",
        "not xml at all",
        "<foo/>",
        "<mujoco><worldbody><geom/></worldbody>",
        "\0",
    ] {
        let err = compile_err(xml);
        assert!(!err.message.is_empty(), "{xml:?}");
    }
}

#[test]
fn missing_mesh_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let xml = r#"<mujoco>
  <asset>
    <mesh name="m" file="does_not_exist.obj"/>
  </asset>
  <worldbody>
    <geom type="mesh" mesh="m"/>
  </worldbody>
</mujoco>"#;
    let err = compile_str(xml, dir.path()).unwrap_err();
    assert!(err.message.contains("does_not_exist.obj"), "{err}");
    assert!(err.message.to_lowercase().contains("error"), "{err}");
}

#[test]
fn missing_model_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let err = compile_file(&dir.path().join("nope.xml")).unwrap_err();
    assert!(err.message.contains("nope.xml"), "{err}");
    let err = compile_file(Path::new("with\0nul.xml")).unwrap_err();
    assert!(err.message.contains("NUL"), "{err}");
}

#[test]
fn compiled_model_is_send_and_sync() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<CompiledModel>();
    let model = compile_str(ARM, here()).unwrap();
    let moved = std::thread::spawn(move || model.sizes().nbody)
        .join()
        .unwrap();
    assert_eq!(moved, 5);
}

/// A chain of `links` hinged links (one motor each); with `mesh`, a mesh geom at its tip.
fn chain(links: usize, mesh: bool) -> String {
    let mut xml = format!("<mujoco model=\"chain{links}\">\n");
    if mesh {
        xml.push_str(
            "  <asset><mesh name=\"tet\" file=\"meshes/tet.obj\" scale=\"0.1 0.1 0.1\"/></asset>\n",
        );
    }
    xml.push_str("  <worldbody>\n");
    for i in 0..links {
        let pos = if i == 0 { "0 0 1" } else { "0.1 0 0" };
        xml.push_str(&format!(
            "<body name=\"link{i}\" pos=\"{pos}\"><joint name=\"j{i}\" axis=\"0 1 0\"/>\
             <geom name=\"g{i}\" type=\"capsule\" fromto=\"0 0 0 0.1 0 0\" size=\"0.02\"/>\n"
        ));
    }
    if mesh {
        xml.push_str("<geom name=\"tip\" type=\"mesh\" mesh=\"tet\"/>\n");
    }
    xml.push_str(&"</body>".repeat(links));
    xml.push_str("\n  </worldbody>\n  <actuator>\n");
    for i in 0..links {
        xml.push_str(&format!("    <motor name=\"m{i}\" joint=\"j{i}\"/>\n"));
    }
    xml.push_str("  </actuator>\n</mujoco>\n");
    xml
}

#[test]
fn eight_threads_compile_concurrently() {
    const THREADS: usize = 8;
    const ROUNDS: usize = 50;
    let mesh_dir = Arc::new(write_mesh_dir(TETRAHEDRON_OBJ));
    let handles: Vec<_> = (0..THREADS)
        .map(|t| {
            let mesh_dir = Arc::clone(&mesh_dir);
            std::thread::spawn(move || {
                let links = t + 1;
                let mesh = t % 2 == 0;
                let xml = chain(links, mesh);
                // Threads 2, 3, 6, 7 load a file from disk, the others a string via the VFS.
                let via_file = t % 4 >= 2;
                let file = mesh_dir.path().join(format!("chain{t}.xml"));
                std::fs::write(&file, &xml).unwrap();
                for round in 0..ROUNDS {
                    let model = if via_file {
                        compile_file(&file)
                    } else {
                        compile_str(&xml, mesh_dir.path())
                    }
                    .unwrap_or_else(|e| panic!("thread {t} round {round}: {e}"));
                    let s = model.sizes();
                    let n = links;
                    let geoms = n + usize::from(mesh);
                    assert_eq!(
                        (s.nbody, s.njnt, s.ngeom, s.nq, s.nv, s.nu, s.nmesh),
                        (n + 1, n, geoms, n, n, n, usize::from(mesh)),
                        "thread {t} round {round}"
                    );
                    assert_eq!(
                        model.names(ObjType::Joint).last().unwrap(),
                        &format!("j{}", n - 1)
                    );
                }
            })
        })
        .collect();
    for handle in handles {
        handle.join().unwrap();
    }
}

/// The build links the MuJoCo whose version build.rs reported
/// (`MJCF_FORGE_MUJOCO_VERSION`): `castshadow` is a geom attribute from MuJoCo 4.0.0 on,
/// which 3.17.0's schema rejects.
#[test]
fn linked_mujoco_is_the_selected_version() {
    let xml = r#"<mujoco><worldbody><geom size="1" castshadow="false"/></worldbody></mujoco>"#;
    let got = compile_str(xml, here());
    let major: u32 = env!("MJCF_FORGE_MUJOCO_VERSION")
        .split('.')
        .next()
        .and_then(|m| m.parse().ok())
        .expect("a version X.Y.Z");
    if major >= 4 {
        let model = got.expect("MuJoCo 4.0.0 reads castshadow");
        assert_eq!(model.sizes().ngeom, 1);
    } else {
        let err = got.expect_err("MuJoCo 3.17.0 has no castshadow");
        assert!(
            err.message.contains("unrecognized attribute: 'castshadow'"),
            "{err}"
        );
    }
}

/// MuJoCo's own entry points, called here as a client of the linked library would.
mod client {
    use std::ffi::{c_char, c_int, c_void};
    unsafe extern "C" {
        pub fn mj_loadXML(
            f: *const c_char,
            vfs: *const c_void,
            e: *mut c_char,
            n: c_int,
        ) -> *mut c_void;
        pub fn mj_saveLastXML(
            f: *const c_char,
            m: *const c_void,
            e: *mut c_char,
            n: c_int,
        ) -> c_int;
        pub fn mj_deleteModel(m: *mut c_void);
    }
}

/// What `mj_saveLastXML` writes for the client's model (MuJoCo's last loaded XML model,
/// process-wide), or None where MuJoCo refuses (the model is not the slot's).
fn saved_last_xml(model: *const std::ffi::c_void, dir: &Path) -> Option<String> {
    let path = std::ffi::CString::new(dir.join("last.xml").to_str().unwrap()).unwrap();
    let mut err = vec![0 as std::ffi::c_char; 1000];
    // SAFETY: `path` is NUL-terminated, `model` a live model of the client's, `err` holds 1000 bytes.
    let ok = unsafe { client::mj_saveLastXML(path.as_ptr(), model, err.as_mut_ptr(), 1000) };
    (ok == 1).then(|| std::fs::read_to_string(dir.join("last.xml")).unwrap())
}

#[test]
fn compiles_leave_mujocos_last_loaded_xml_to_the_process() {
    // A client loads its model (MuJoCo keeps it for mj_saveLastXML); our compiles, of
    // strings, files and failing models, on threads too, leave that slot as it was.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("client.xml");
    std::fs::write(
        &file,
        r#"<mujoco model="client"><worldbody><body name="ours_not"><geom size="0.1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let path = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
    let mut err = vec![0 as std::ffi::c_char; 1000];
    // SAFETY: as above; the model is freed at the end of the test.
    let model =
        unsafe { client::mj_loadXML(path.as_ptr(), std::ptr::null(), err.as_mut_ptr(), 1000) };
    assert!(!model.is_null());
    let before = saved_last_xml(model, dir.path()).expect("the client's model is the slot's");
    assert!(before.contains(r#"model="client""#), "{before}");

    let other = dir.path().join("other.xml");
    std::fs::write(
        &other,
        r#"<mujoco model="other"><worldbody><geom size="1"/></worldbody></mujoco>"#,
    )
    .unwrap();
    compile_str(
        r#"<mujoco model="ours"><worldbody><geom size="1"/></worldbody></mujoco>"#,
        here(),
    )
    .unwrap();
    compile_file(&other).unwrap();
    assert!(
        compile_str(
            "<mujoco><worldbody><geom type='mesh' mesh='no'/></worldbody></mujoco>",
            here()
        )
        .is_err()
    );
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| compile_file(&other).unwrap());
        }
    });
    assert_eq!(
        saved_last_xml(model, dir.path()).as_deref(),
        Some(before.as_str())
    );
    // SAFETY: made by mj_loadXML above, not used afterwards.
    unsafe { client::mj_deleteModel(model) };
}
