#!/usr/bin/env python3
"""Peer benchmark of the path tracer (issue #40): renders one glTF scene with this project's
`host render`, Blender Cycles (PyPI `bpy`) and Mitsuba 3 (PyPI `mitsuba`, variants scalar_rgb and
llvm_ad_rgb) on the CPU with the same thread count, and reports for each the time to reach a
relative RMSE against its own converged reference, samples per second, and whether the
references agree. See README.md beside this file.

Run: python3 benches/peers/peers.py [--quick] [--scene S.gltf] [--report out/peers.md]
(`--setup` creates the Python environment it needs, ~/.cache/peer-bench-venv.)
"""

import argparse
import base64
import json
import math
import os
import platform
import shlex
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
VENV = Path.home() / ".cache" / "peer-bench-venv"
VENV_PY = VENV / "bin" / "python"
# What --setup installs (versions this script was validated with in the README).
PACKAGES = ["numpy", "OpenEXR", "bpy", "mitsuba"]
RENDERERS = ["host", "cycles", "mitsuba-scalar", "mitsuba-llvm"]
# What each part of the script imports, by renderer (the main process needs numpy and OpenEXR).
NEEDS = {"main": ["numpy", "OpenEXR"], "cycles": ["bpy"], "mitsuba-scalar": ["mitsuba", "drjit"], "mitsuba-llvm": ["mitsuba", "drjit"]}
PIP_NAME = {"drjit": "mitsuba", "OpenEXR": "OpenEXR"}
MITSUBA_SAMPLERS = ["independent", "multijitter", "orthogonal", "ldsampler"]
# Mitsuba llvm renders all of a render's samples as one wavefront; more than this many lanes
# (pixels x spp) go in several passes (each pass a render with its own seed, averaged).
LLVM_MAX_LANES = 1 << 22


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# Environment


def missing_modules(names):
    import importlib.util

    return [n for n in names if importlib.util.find_spec(n) is None]


def install_hint(mods):
    pkgs = sorted({PIP_NAME.get(m, m) for m in mods})
    return (
        f"missing Python package(s): {', '.join(pkgs)} (modules {', '.join(mods)}).\n"
        f"  Create the environment with: python3 {Path(__file__).relative_to(REPO) if Path(__file__).is_relative_to(REPO) else __file__} --setup\n"
        f"  (= python3 -m venv {VENV} && {VENV_PY} -m pip install {' '.join(PACKAGES)}; bpy needs CPython 3.11),\n"
        f"  or install them into the Python that runs this script: pip install {' '.join(pkgs)}"
    )


def setup_venv():
    """--setup: the virtual environment with every package the benchmark imports."""
    if sys.version_info[:2] != (3, 11):
        log(f"note: this is Python {platform.python_version()}; bpy's wheels are built for CPython 3.11 only (pip may find no bpy)")
    if not VENV_PY.exists():
        log(f"creating {VENV} (python3 -m venv)")
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    log(f"installing into {VENV}: {' '.join(PACKAGES)} (about 1.2 GB, mostly bpy)")
    t = time.time()
    subprocess.run([str(VENV_PY), "-m", "pip", "install", "--upgrade", "pip"], check=True)
    subprocess.run([str(VENV_PY), "-m", "pip", "install", *PACKAGES], check=True)
    log(f"installed in {time.time() - t:.0f} s; run the benchmark with {VENV_PY} {__file__} (or python3: it switches to the environment itself)")


def maybe_reexec(modules):
    """Run under the benchmark's virtual environment when this Python lacks `modules`."""
    miss = missing_modules(modules)
    if not miss:
        return
    if VENV_PY.exists() and Path(sys.prefix).resolve() != VENV.resolve() and not os.environ.get("PEERS_NO_REEXEC"):
        log(f"{sys.executable} lacks {', '.join(miss)}: running under {VENV_PY}")
        os.environ["PEERS_NO_REEXEC"] = "1"
        os.execv(str(VENV_PY), [str(VENV_PY), __file__, *sys.argv[1:]])
    sys.exit("error: " + install_hint(miss))


def find_libllvm():
    """A libLLVM recent enough for Dr.Jit: $DRJIT_LIBLLVM_PATH, else the Rust toolchain's."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    try:
        sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    # the real library, not the small linker script beside it
    libs = [p for p in (Path(sysroot) / "lib").glob("libLLVM*.so*") if p.is_file() and p.stat().st_size > 1 << 20]
    return str(max(libs, key=lambda p: p.stat().st_size)) if libs else None


def machine_info():
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        up = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        up = "load " + " ".join(f"{x:.2f}" for x in os.getloadavg())
    return {"cpu": cpu, "cores": os.cpu_count(), "uptime": up, "python": platform.python_version(), "platform": platform.platform()}


# ---------------------------------------------------------------------------------------------
# glTF reading (the Mitsuba conversion, and the camera and lights for Cycles)


class Gltf:
    """The parts of a glTF 2.0 file the peers need, in world space (node transforms applied):
    triangle primitives, materials (factors), the cameras in node traversal order (host's camera
    0 is the first), punctual lights, and whether the scene has any light of its own."""

    COMPONENT = {5120: "i1", 5121: "u1", 5122: "i2", 5123: "u2", 5125: "u4", 5126: "f4"}
    NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}

    def __init__(self, path):
        import numpy as np

        self.np = np
        self.path = Path(path)
        self.warnings = []
        raw = self.path.read_bytes()
        glb_bin = None
        if raw[:4] == b"glTF":
            _, _, length = struct.unpack_from("<III", raw, 0)
            off, doc = 12, None
            while off < length:
                clen, ctype = struct.unpack_from("<II", raw, off)
                chunk = raw[off + 8 : off + 8 + clen]
                if ctype == 0x4E4F534A:
                    doc = json.loads(chunk)
                elif ctype == 0x004E4942:
                    glb_bin = chunk
                off += 8 + clen
            self.doc = doc
        else:
            self.doc = json.loads(raw)
        self.buffers = []
        for i, b in enumerate(self.doc.get("buffers", [])):
            uri = b.get("uri")
            if uri is None:
                self.buffers.append(glb_bin)
            elif uri.startswith("data:"):
                self.buffers.append(base64.b64decode(uri.split(",", 1)[1]))
            else:
                from urllib.parse import unquote

                self.buffers.append((self.path.parent / unquote(uri)).read_bytes())
        self.materials = [self._material(i, m) for i, m in enumerate(self.doc.get("materials", []))]
        self.default_material = {"name": "default", "base_color": [1.0, 1.0, 1.0], "metallic": 1.0, "roughness": 1.0, "emissive": [0.0, 0.0, 0.0], "double_sided": False, "transmission": 0.0, "ior": 1.5}
        self.meshes, self.cameras, self.lights = [], [], []
        scenes = self.doc.get("scenes", [])
        roots = scenes[self.doc.get("scene", 0)]["nodes"] if scenes else list(range(len(self.doc.get("nodes", []))))
        for n in roots:
            self._node(n, np.eye(4))
        self.has_lights = bool(self.lights) or any(max(m["material"]["emissive"]) > 0 for m in self.meshes)

    def accessor(self, i):
        np = self.np
        a = self.doc["accessors"][i]
        n = self.NCOMP[a["type"]]
        dt = np.dtype("<" + self.COMPONENT[a["componentType"]])
        if "sparse" in a:
            raise SystemExit(f"error: {self.path}: accessor {i} is sparse; the benchmark's glTF reader does not read sparse accessors")
        if "bufferView" not in a:
            out = np.zeros((a["count"], n), dtype=dt)
        else:
            bv = self.doc["bufferViews"][a["bufferView"]]
            stride = bv.get("byteStride") or dt.itemsize * n
            off = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
            out = np.ndarray((a["count"], n), dtype=dt, buffer=self.buffers[bv["buffer"]], offset=off, strides=(stride, dt.itemsize)).copy()
        if a.get("normalized") and dt.kind in "iu":
            out = np.maximum(out.astype(np.float64) / np.iinfo(dt).max, -1.0)
        return out

    def _material(self, i, m):
        pbr = m.get("pbrMetallicRoughness", {})
        ext = m.get("extensions", {})
        strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        textures = [k for k in ("baseColorTexture", "metallicRoughnessTexture") if k in pbr] + [k for k in ("normalTexture", "emissiveTexture", "occlusionTexture") if k in m]
        if textures:
            self.warnings.append(f"material {i} ({m.get('name', '')!r}): textures {', '.join(textures)} are not converted for Mitsuba (its factors are)")
        if m.get("alphaMode", "OPAQUE") != "OPAQUE":
            self.warnings.append(f"material {i} ({m.get('name', '')!r}): alphaMode {m['alphaMode']} is not converted for Mitsuba (opaque)")
        return {
            "name": m.get("name", f"material {i}"),
            "base_color": list(pbr.get("baseColorFactor", [1, 1, 1, 1]))[:3],
            "metallic": float(pbr.get("metallicFactor", 1.0)),
            "roughness": float(pbr.get("roughnessFactor", 1.0)),
            "emissive": [float(e) * strength for e in m.get("emissiveFactor", [0, 0, 0])],
            "double_sided": bool(m.get("doubleSided", False)),
            "transmission": float(ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0)),
            "ior": float(ext.get("KHR_materials_ior", {}).get("ior", 1.5)),
        }

    def _local(self, node):
        np = self.np
        if "matrix" in node:
            return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
        t = np.array(node.get("translation", [0, 0, 0]), dtype=np.float64)
        x, y, z, w = node.get("rotation", [0, 0, 0, 1])
        s = np.array(node.get("scale", [1, 1, 1]), dtype=np.float64)
        r = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        m = np.eye(4)
        m[:3, :3] = r * s
        m[:3, 3] = t
        return m

    def _node(self, index, parent):
        np = self.np
        node = self.doc["nodes"][index]
        world = parent @ self._local(node)
        m3 = world[:3, :3]
        if "mesh" in node:
            mesh = self.doc["meshes"][node["mesh"]]
            for k, prim in enumerate(mesh["primitives"]):
                self._primitive(f"{mesh.get('name', 'mesh ' + str(node['mesh']))} {k}", prim, world)
        origin = world[:3, 3]
        forward = m3 @ np.array([0.0, 0.0, -1.0])
        forward /= np.linalg.norm(forward)
        if "camera" in node:
            cam = self.doc["cameras"][node["camera"]]
            up = m3 @ np.array([0.0, 1.0, 0.0])
            up = up - forward * up.dot(forward)
            up /= np.linalg.norm(up)
            self.cameras.append({"name": cam.get("name", node.get("name", f"camera {node['camera']}")), "type": cam["type"], "yfov": cam.get("perspective", {}).get("yfov"), "position": origin.tolist(), "forward": forward.tolist(), "up": up.tolist()})
        light = node.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
        if light is not None:
            L = self.doc["extensions"]["KHR_lights_punctual"]["lights"][light]
            col = [c * L.get("intensity", 1.0) for c in L.get("color", [1, 1, 1])]
            spot = L.get("spot", {})
            self.lights.append({"name": L.get("name", f"light {light}"), "type": L["type"], "intensity": col, "position": origin.tolist(), "direction": forward.tolist(), "inner": spot.get("innerConeAngle", 0.0), "outer": spot.get("outerConeAngle", math.pi / 4)})
        for c in node.get("children", []):
            self._node(c, world)

    def _primitive(self, name, prim, world):
        np = self.np
        if prim.get("mode", 4) != 4:
            self.warnings.append(f"{name}: primitive mode {prim['mode']} (not triangles) skipped")
            return
        attrs = prim["attributes"]
        p = self.accessor(attrs["POSITION"]).astype(np.float64)
        idx = self.accessor(prim["indices"]).reshape(-1, 3).astype(np.uint32) if "indices" in prim else np.arange(len(p), dtype=np.uint32).reshape(-1, 3)
        m3 = world[:3, :3]
        pw = (p @ m3.T + world[:3, 3]).astype(np.float32)
        nrm = None
        if "NORMAL" in attrs:
            n = self.accessor(attrs["NORMAL"]).astype(np.float64) @ np.linalg.inv(m3)
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            nrm = n.astype(np.float32)
        uv = self.accessor(attrs["TEXCOORD_0"]).astype(np.float32) if "TEXCOORD_0" in attrs else None
        if np.linalg.det(m3) < 0:
            idx = idx[:, [0, 2, 1]]
        mat = self.materials[prim["material"]] if "material" in prim else self.default_material
        self.meshes.append({"name": name, "positions": pw, "normals": nrm, "uvs": uv, "indices": np.ascontiguousarray(idx), "material": mat})

    def camera(self, which=0):
        if not self.cameras:
            raise SystemExit(f"error: {self.path}: no camera; the benchmark renders the glTF camera 0 (host would frame the scene itself; add a camera)")
        c = self.cameras[which]
        if c["type"] != "perspective":
            raise SystemExit(f"error: {self.path}: camera {which} is {c['type']}; the benchmark converts perspective cameras only")
        return c


# ---------------------------------------------------------------------------------------------
# Workers: one process per peer renderer (imports, threads and JIT state stay separate); each
# reads a job (scene, size, renders), writes every render as .npy and its times as JSON.


def worker_cycles(job):
    import warnings

    import numpy as np
    import bpy

    warnings.filterwarnings("ignore", category=DeprecationWarning)  # use_nodes (Blender 6 drops it)

    g = Gltf(job["scene"])
    cam = g.camera(0)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    # COMPAT: punctual light intensities as radiometric quantities (W/sr, W/m^2) as host reads
    # them, without the 683 lm/W photometric conversion.
    bpy.ops.import_scene.gltf(filepath=str(job["scene"]), export_import_convert_lighting_mode="COMPAT")
    sc = bpy.context.scene
    # our camera from the glTF camera 0, glTF (x, y, z) = Blender (x, -z, y) as the importer maps it
    from mathutils import Matrix, Vector

    def b(v):
        return Vector((v[0], -v[2], v[1]))

    f, u, p = b(cam["forward"]), b(cam["up"]), b(cam["position"])
    r = f.cross(u)
    cd = bpy.data.cameras.new("peers camera")
    cd.type = "PERSP"
    cd.sensor_fit = "VERTICAL"
    cd.angle_y = cam["yfov"]
    cd.clip_start = 1e-5
    cd.clip_end = 1e8
    co = bpy.data.objects.new("peers camera", cd)
    sc.collection.objects.link(co)
    co.matrix_world = Matrix(((r.x, u.x, -f.x, p.x), (r.y, u.y, -f.y, p.y), (r.z, u.z, -f.z, p.z), (0, 0, 0, 1)))
    sc.camera = co
    for o in sc.objects:
        if o.type == "LIGHT" and hasattr(o.data, "shadow_soft_size"):
            o.data.shadow_soft_size = 0.0  # punctual
    # world: a uniform radiance 1 when the scene has no light (host's default), else black
    w = bpy.data.worlds.new("peers world")
    w.use_nodes = True
    bg = next(n for n in w.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (1, 1, 1, 1) if not g.has_lights else (0, 0, 0, 1)
    bg.inputs["Strength"].default_value = 1.0
    sc.world = w
    # glTF emission is one-sided unless doubleSided; Cycles' is two-sided: mask the back face.
    single = {m["name"] for m in g.materials if not m["double_sided"]}
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        if mat.name not in single and mat.name.rsplit(".", 1)[0] not in single:
            continue  # double sided (the importer's names: the glTF name, or it with .001 added)
        for node in mat.node_tree.nodes:
            if node.type != "BSDF_PRINCIPLED":
                continue
            s = node.inputs["Emission Strength"]
            col = node.inputs["Emission Color"].default_value
            if s.is_linked or s.default_value <= 0 or max(col[:3]) <= 0:
                continue
            nt = mat.node_tree
            geo = nt.nodes.new("ShaderNodeNewGeometry")
            front = nt.nodes.new("ShaderNodeMath")
            front.operation = "SUBTRACT"
            front.inputs[0].default_value = 1.0
            nt.links.new(geo.outputs["Backfacing"], front.inputs[1])
            mul = nt.nodes.new("ShaderNodeMath")
            mul.operation = "MULTIPLY"
            mul.inputs[1].default_value = s.default_value
            nt.links.new(front.outputs[0], mul.inputs[0])
            nt.links.new(mul.outputs[0], s)
            mat.cycles.emission_sampling = "FRONT"
    rd = sc.render
    rd.engine = "CYCLES"
    rd.resolution_x, rd.resolution_y, rd.resolution_percentage = job["width"], job["height"], 100
    rd.pixel_aspect_x = rd.pixel_aspect_y = 1.0
    rd.film_transparent = False
    rd.threads_mode = "FIXED"
    rd.threads = job["threads"]
    rd.image_settings.file_format = "OPEN_EXR"
    rd.image_settings.color_depth = "32"
    rd.image_settings.exr_codec = "NONE"
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    cy = sc.cycles
    cy.device = "CPU"
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.time_limit = 0.0
    bounces = job["max_depth"] - 1  # host's depth 1 (direct lighting) = Cycles' 0 bounces
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = bounces
    cy.volume_bounces = 0
    cy.transparent_max_bounces = max(8, job["max_depth"])
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.use_animated_seed = False
    cy.use_guiding = False
    info = {"renderer": "cycles", "version": f"Blender {bpy.app.version_string} (bpy)", "sampling_pattern": cy.sampling_pattern, "light_tree": cy.use_light_tree, "max_bounces": bounces, "world": "uniform 1" if not g.has_lights else "black", "objects": len(sc.objects), "renders": []}
    out = Path(job["dir"])
    # Each render call syncs the scene and builds the BVH again (persistent data does not
    # re-render in the bpy module); host's render time leaves its load and BVH build out, so
    # the time here is Cycles' own sampling phase: from its "Sample 0/N" status to "Finished",
    # as its render_stats handler reports them.
    stats = []
    bpy.app.handlers.render_stats.append(lambda *a: stats.append((time.perf_counter(), str(a[0]) if a else "")))

    def render(spp, seed):
        cy.samples, cy.seed = spp, seed
        stats.clear()
        c0, t = cpu_seconds(), time.perf_counter()
        bpy.ops.render.render()
        t1, c1 = time.perf_counter(), cpu_seconds()
        start = next((ts for ts, m in stats if "Sample 0/" in m), None)
        end = next((ts for ts, m in reversed(stats) if m.endswith("Finished")), t1)
        return (end - start if start is not None else t1 - t), t1 - t, start is not None, (c1 - c0) / (t1 - t)

    render(1, 0)  # warm-up: loads the kernels
    for r in job["renders"]:
        dt, call, staged, busy = render(r["spp"], r["seed"])
        exr = out / f"cycles-{r['name']}.exr"
        bpy.data.images["Render Result"].save_render(str(exr), scene=sc)
        np.save(out / f"cycles-{r['name']}.npy", read_exr(exr))
        exr.unlink()
        info["renders"].append({**r, "seconds": dt, "call_seconds": call, "spp_rendered": r["spp"], "cores_busy": busy, "timing": "sampling phase (render_stats)" if staged else "render call"})
        log(f"  cycles {r['name']}: {r['spp']} spp in {dt:.3f} s (render call {call:.3f} s with sync and BVH)")
    return info


def mitsuba_scene(g, job, mi):
    import numpy as np

    cam = g.camera(0)
    scene = {"type": "scene"}
    scene["integrator"] = {"type": "path", "max_depth": job["max_depth"] + 1}  # host's 1 (direct lighting) = Mitsuba's 2
    sampler = {"type": job["mitsuba_sampler"], "sample_count": 4}
    p = cam["position"]
    target = [p[k] + cam["forward"][k] for k in range(3)]
    scene["sensor"] = {
        "type": "perspective",
        "fov": math.degrees(cam["yfov"]),
        "fov_axis": "y",
        "near_clip": 1e-5,
        "far_clip": 1e8,
        "to_world": mi.ScalarTransform4f.look_at(origin=p, target=target, up=cam["up"]),
        "film": {"type": "hdrfilm", "width": job["width"], "height": job["height"], "rfilter": {"type": "box"}, "pixel_format": "rgb", "component_format": "float32", "sample_border": False},
        "sampler": sampler,
    }
    if not g.has_lights:
        scene["environment"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    bsdfs = {}
    for k, m in enumerate(g.meshes):
        mat = m["material"]
        key = id(mat)
        if key not in bsdfs:
            pr = {"type": "principled", "base_color": {"type": "rgb", "value": mat["base_color"]}, "metallic": mat["metallic"], "roughness": mat["roughness"], "specular": 0.5}
            if job["mitsuba_bsdf"] == "diffuse" and mat["metallic"] == 0 and mat["transmission"] == 0:
                pr = {"type": "diffuse", "reflectance": {"type": "rgb", "value": mat["base_color"]}}
            if mat["transmission"] > 0:
                pr.update(spec_trans=mat["transmission"] * (1 - mat["metallic"]), eta=mat["ior"])
                bsdfs[key] = mi.load_dict(pr)
            else:
                # host's BSDF shades both faces alike (the glTF BxDF of either hemisphere)
                bsdfs[key] = mi.load_dict({"type": "twosided", "bsdf": pr})
        props = mi.Properties()
        props["bsdf"] = bsdfs[key]
        if max(mat["emissive"]) > 0:
            if mat["double_sided"]:
                g.warnings.append(f"{m['name']}: double-sided emission emits from the front faces only in Mitsuba")
            props["emitter"] = mi.load_dict({"type": "area", "radiance": {"type": "rgb", "value": mat["emissive"]}})
        pos, idx, nrm, uv = m["positions"], m["indices"], m["normals"], m["uvs"]
        mesh = mi.Mesh(f"mesh{k}", vertex_count=len(pos), face_count=len(idx), has_vertex_normals=nrm is not None, has_vertex_texcoords=uv is not None, props=props)
        prm = mi.traverse(mesh)
        prm["vertex_positions"] = type(prm["vertex_positions"])(np.ascontiguousarray(pos, dtype=np.float32).ravel())
        prm["faces"] = type(prm["faces"])(np.ascontiguousarray(idx, dtype=np.uint32).ravel())
        if nrm is not None:
            prm["vertex_normals"] = type(prm["vertex_normals"])(np.ascontiguousarray(nrm, dtype=np.float32).ravel())
        if uv is not None:
            # glTF's (0, 0) is the image's top-left, Mitsuba's its bottom-left
            uvm = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1).astype(np.float32)
            prm["vertex_texcoords"] = type(prm["vertex_texcoords"])(uvm.ravel())
        prm.update()
        scene[f"mesh{k}"] = mesh
    for k, L in enumerate(g.lights):
        rgb = {"type": "rgb", "value": L["intensity"]}
        if L["type"] == "point":
            scene[f"light{k}"] = {"type": "point", "position": L["position"], "intensity": rgb}
        elif L["type"] == "spot":
            p = L["position"]
            t = [p[i] + L["direction"][i] for i in range(3)]
            up = [0, 1, 0] if abs(L["direction"][1]) < 0.9 else [1, 0, 0]
            scene[f"light{k}"] = {"type": "spot", "intensity": rgb, "cutoff_angle": math.degrees(L["outer"]), "beam_width": math.degrees(L["inner"]), "to_world": mi.ScalarTransform4f.look_at(origin=p, target=t, up=up)}
            g.warnings.append(f"light {L['name']!r}: Mitsuba's spot falloff between the cone angles differs from glTF's")
        else:
            scene[f"light{k}"] = {"type": "directional", "direction": L["direction"], "irradiance": rgb}
    return scene


def worker_mitsuba(job):
    import numpy as np

    variant = job["variant"]
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(variant)
    dr.set_thread_count(job["threads"])  # Dr.Jit's pool renders both variants' image blocks
    mi.set_log_level(mi.LogLevel.Warn)
    g = Gltf(job["scene"])
    scene = mi.load_dict(mitsuba_scene(g, job, mi))
    llvm = variant.startswith("llvm")
    pixels = job["width"] * job["height"]
    sampler = scene.sensors()[0].sampler()
    info = {"renderer": job["name"], "version": f"Mitsuba {mi.__version__} ({variant}, Dr.Jit {dr.__version__})", "sampler": job["mitsuba_sampler"], "bsdf": job["mitsuba_bsdf"], "max_depth": job["max_depth"] + 1, "warnings": g.warnings, "renders": [], "threads": dr.thread_count()}
    if llvm:
        info["libllvm"] = os.environ.get("DRJIT_LIBLLVM_PATH", "(Dr.Jit's search)")
        dr.set_flag(dr.JitFlag.KernelHistory, True)

    def seed_of(s):
        # an opaque seed: one compiled kernel serves every seed
        return dr.opaque(mi.UInt32, s) if llvm else s

    def render(spp, seed):
        """One render at `spp` (llvm: in passes of at most LLVM_MAX_LANES lanes); returns the
        image, seconds, the JIT compile seconds excluded from them, and the spp the sampler
        took (stratified samplers round it)."""
        per = max(1, min(spp, LLVM_MAX_LANES // pixels)) if llvm else spp
        passes = [per] * (spp // per) + ([spp % per] if spp % per else [])
        acc, took, compile_s = None, 0, 0.0
        c0, t = cpu_seconds(), time.perf_counter()
        for k, n in enumerate(passes):
            img = mi.render(scene, spp=n, seed=seed_of(seed * 4096 + k if len(passes) > 1 else seed))
            if llvm:
                dr.eval(img)
                dr.sync_thread()
                for h in dr.kernel_history():
                    if h.get("cache_hit") == 0:
                        compile_s += (h.get("codegen_time", 0.0) + h.get("backend_time", 0.0)) / 1000.0
            a = np.array(img, dtype=np.float64)
            m = sampler.sample_count()
            acc = a * m if acc is None else acc + a * m
            took += m
        wall = time.perf_counter() - t
        busy = (cpu_seconds() - c0) / wall
        return (acc / took).astype(np.float32), wall - compile_s, compile_s, took, busy

    # warm-up (untimed): llvm compiles its kernels here (spp 1 and spp > 1 are two kernels)
    t = time.perf_counter()
    for n in (1, 2):
        render(n, 0)
    info["warmup_seconds"] = time.perf_counter() - t
    for r in job["renders"]:
        img, dt, cs, took, busy = render(r["spp"], r["seed"])
        np.save(Path(job["dir"]) / f"{job['name']}-{r['name']}.npy", img)
        info["renders"].append({**r, "seconds": dt, "jit_compile_seconds_excluded": cs, "spp_rendered": took, "cores_busy": busy})
        log(f"  {job['name']} {r['name']}: {took} spp in {dt:.3f} s" + (f" (+{cs:.3f} s JIT compile, excluded)" if cs else ""))
    return info


def cpu_seconds():
    """User + system CPU seconds of this process, all its threads."""
    t = os.times()
    return t.user + t.system


def read_exr(path):
    import numpy as np
    import OpenEXR

    ch = OpenEXR.File(str(path)).channels()
    if "RGB" in ch:
        a = ch["RGB"].pixels
    elif "RGBA" in ch:
        a = ch["RGBA"].pixels[..., :3]
    else:
        a = np.stack([ch[c].pixels for c in ("R", "G", "B")], axis=-1)
    return np.asarray(a, dtype=np.float32)


def run_host(args, job, work):
    """This project: one `host render` per render; the time is the JSON's render_seconds."""
    import numpy as np

    host = Path(args.host)
    if not host.exists():
        raise SystemExit(f"error: {host} not found: build it with `cargo build --release -p host` (or give --host)")
    extra = shlex.split(args.host_args or "")
    test_extra = shlex.split(args.host_test_args or "")
    info = {"renderer": "host", "version": host_version(host), "host_args": extra, "host_test_args": test_extra, "renders": []}
    for r in job["renders"]:
        out = work / f"host-{r['name']}.exr"
        cmd = [str(host), "render", str(job["scene"]), "--device", "cpu", "--threads", str(args.threads), "--width", str(job["width"]), "--height", str(job["height"])]
        cmd += ["--spp", str(r["spp"]), "--seed", str(r["seed"]), "--max-depth", str(job["max_depth"]), "-o", str(out), "--quiet", *extra]
        if not r["name"].startswith("ref"):
            cmd += test_extra
        import resource

        r0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        r1, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter() - t0
        busy = (r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime) / wall
        if p.returncode != 0:
            raise RuntimeError(f"{shlex.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
        summary = json.loads(out.with_suffix(".json").read_text())
        info.setdefault("notices", summary.get("warnings", []))
        info["settings"] = {k: summary[k] for k in ("backend", "threads", "sampler", "strategy", "compensation", "max_depth", "rr_depth", "spp_per_pass", "environment") if k in summary}
        if "sampler" in summary and "sampler" not in info["version"]:
            info["version"] += f" ({summary['sampler']} sampler)"
        np.save(work / f"host-{r['name']}.npy", read_exr(out))
        mean_spp = (summary.get("adaptive") or {}).get("mean_spp")
        info["renders"].append({**r, "seconds": summary["render_seconds"], "spp_rendered": summary["samples_per_pixel"], "mean_pixel_spp": mean_spp, "cores_busy": busy, "process_seconds": wall, "command": shlex.join(cmd)})
        log(f"  host {r['name']}: {r['spp']} spp in {summary['render_seconds']:.3f} s")
    return info


def host_version(host):
    try:
        rev = subprocess.run(["git", "-C", str(REPO), "describe", "--always", "--dirty"], capture_output=True, text=True).stdout.strip()
    except OSError:
        rev = ""
    return f"host {rev}".strip()


def run_worker(name, job, work, args):
    """A peer in its own process (this script with --worker); returns its info, or raises."""
    env = dict(os.environ)
    if name == "mitsuba-llvm":
        lib = find_libllvm()
        if lib:
            env["DRJIT_LIBLLVM_PATH"] = lib
        else:
            log("warning: no libLLVM found for Dr.Jit (set DRJIT_LIBLLVM_PATH); Debian 12's LLVM 15 crashes it")
    need = missing_modules(NEEDS[name])
    if need:
        raise RuntimeError(install_hint(need))
    jf = work / f"{name}-job.json"
    jf.write_text(json.dumps(job))
    # stdout has Blender's and Mitsuba's chatter: shown only when the worker fails
    p = subprocess.run([sys.executable, __file__, "--worker", str(jf)], env=env, stdout=subprocess.PIPE, text=True)
    res = work / f"{name}-result.json"
    if p.returncode != 0 or not res.exists():
        tail = "\n".join(p.stdout.splitlines()[-20:])
        raise RuntimeError(f"{name}: the worker failed (exit {p.returncode}); its stderr is above, the end of its stdout:\n{tail}")
    return json.loads(res.read_text())


def worker_main(job_file):
    job = json.loads(Path(job_file).read_text())
    info = worker_cycles(job) if job["name"] == "cycles" else worker_mitsuba(job)
    (Path(job["dir"]) / f"{job['name']}-result.json").write_text(json.dumps(info))


# ---------------------------------------------------------------------------------------------
# Metrics


def rel_rmse(x, r1, r2):
    """Relative RMSE of x against ref = (r1 + r2) / 2, less the reference's own noise."""
    import numpy as np

    ref = 0.5 * (r1 + r2)
    mse = float(np.mean((x - ref) ** 2))
    ref_var = float(np.mean((r1 - r2) ** 2)) / 4.0
    return math.sqrt(max(0.0, mse - ref_var)) / float(np.mean(ref)), math.sqrt(ref_var) / float(np.mean(ref))


def fit(times, errs, target):
    import numpy as np

    pts = [(t, e) for t, e in zip(times, errs) if t > 0 and e > 0 and math.isfinite(e)]
    if len(pts) < 2:
        return None, None, None
    lt, le = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    b, a = np.polyfit(lt, le, 1)
    t = math.exp((math.log(target) - a) / b) if b < 0 else float("nan")
    return float(a), float(b), t


def blocks(img, n=4):
    """Means of an n x n grid of image blocks, per channel."""
    import numpy as np

    h, w = img.shape[:2]
    ys, xs = np.linspace(0, h, n + 1).astype(int), np.linspace(0, w, n + 1).astype(int)
    return np.array([[img[ys[i] : ys[i + 1], xs[j] : xs[j + 1]].reshape(-1, 3).mean(axis=0) for j in range(n)] for i in range(n)])


def analyse(name, info, work, args):
    import numpy as np

    imgs = {r["name"]: np.load(work / f"{name}-{r['name']}.npy").astype(np.float64) for r in info["renders"]}
    r1, r2 = imgs["ref1"], imgs["ref2"]
    pix = args.width * args.height
    rungs = []
    for r in info["renders"]:
        if not r["name"].startswith("spp"):
            continue
        e, ref_noise = rel_rmse(imgs[r["name"]], r1, r2)
        rungs.append({"spp": r["spp_rendered"], "seconds": r["seconds"], "err": e, "msamples_per_s": pix * r["spp_rendered"] / r["seconds"] / 1e6, "cores_busy": r.get("cores_busy")})
    a, b, t = fit([x["seconds"] for x in rungs], [x["err"] for x in rungs], args.target)
    top = rungs[-1]
    return {"ref_noise": ref_noise, "rungs": rungs, "fit_a": a, "slope": b, "time_to_target": t, "msamples_per_s": top["msamples_per_s"], "err_top": top["err"], "spp_top": top["spp"], "ref_mean": float(np.mean(0.5 * (r1 + r2))), "ref": 0.5 * (r1 + r2)}


def agreement(base, other):
    import numpy as np

    m = float(np.mean(base))
    rel_mean = float(np.mean(other)) / m - 1.0
    d = (blocks(other) - blocks(base)) / m
    return rel_mean, float(np.sqrt(np.mean(d**2)))


def fmt(v, spec):
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def report(args, mach, results, failed, scene_note):
    lines = [f"# Peer benchmark: {Path(args.scene).name} at {args.width}x{args.height}", ""]
    lines += [f"Machine: {mach['cpu']}, {mach['cores']} cores; `uptime`: {mach['uptime']}", ""]
    lines += [
        f"Settings: scene `{args.scene}`{scene_note}; {args.threads} threads each; host --max-depth {args.max_depth} (Cycles max_bounces {args.max_depth - 1}, Mitsuba max_depth {args.max_depth + 1});"
        f" references 2 x {args.ref_spp} spp per renderer; ladder {', '.join(map(str, args.ladder))} spp; target relative RMSE {args.target}; seed base {args.seed};"
        f" Mitsuba sampler {args.mitsuba_sampler}, materials {args.mitsuba_bsdf}; host args `{args.host_args or ''}`, ladder only `{args.host_test_args or ''}`.",
        "",
        "err = sqrt(max(0, mean((X - ref)^2) - mean((R1 - R2)^2) / 4)) / mean(ref), ref = (R1 + R2) / 2 of the renderer's own halves;"
        " time to target from the least-squares fit log err = a + b log time over the ladder.",
        "",
    ]
    h = results.get("host")
    top = max(args.ladder)
    lines += [f"| renderer | version | M samples/s | err @ {top} spp | slope b | time to err {args.target} (s) | host / it | mean vs host | 4x4 blocks RMS vs host |", "|---|---|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        ratio = h["time_to_target"] / r["time_to_target"] if h and r["time_to_target"] and h["time_to_target"] and math.isfinite(r["time_to_target"]) else None
        lines.append(
            f"| {name} | {r['version']} | {fmt(r['msamples_per_s'], '.3f')} | {fmt(r['err_top'], '.4f')} | {fmt(r['slope'], '.3f')} | {fmt(r['time_to_target'], '.3f')} | {fmt(ratio, '.3f')} |"
            f" {fmt(r.get('mean_vs_host'), '+.4f')} | {fmt(r.get('blocks_vs_host'), '.4f')} |"
        )
    for name, why in failed.items():
        lines.append(f"| {name} | failed: {why.splitlines()[0][:150]} | | | | | | | |")
    lines += ["", "Ladder (each render's own seed; seconds = render time only; cores busy = CPU s / wall s of the render call, for host of the whole `host render` process):", ""]
    lines += ["| renderer | spp | seconds | M samples/s | err | cores busy |", "|---|---|---|---|---|---|"]
    for name, r in results.items():
        for x in r["rungs"]:
            lines.append(f"| {name} | {x['spp']} | {x['seconds']:.4f} | {x['msamples_per_s']:.3f} | {x['err']:.4f} | {fmt(x['cores_busy'], '.2f')} |")
    lines += ["", "Reference noise (relative RMSE of ref = (R1 + R2)/2 itself): " + ", ".join(f"{n} {r['ref_noise']:.4f}" for n, r in results.items())]
    notes = []
    for name, r in results.items():
        for w in r.get("warnings", []) + r.get("notices", []):
            notes.append(f"- {name}: {w}")
    if notes:
        lines += ["", "Notes:", "", *notes]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=str(REPO / "scenes/cornell_box/cornell_box.gltf"), help="glTF 2.0 scene (.gltf or .glb); `host render --write-scene F.gltf` writes the built-in one")
    ap.add_argument("--width", type=int, help="image width (default 256; --quick 64)")
    ap.add_argument("--height", type=int, help="image height (default 256; --quick 64)")
    ap.add_argument("--renderers", default=",".join(RENDERERS), help=f"comma-separated, of {','.join(RENDERERS)}")
    ap.add_argument("--ladder", help="spp of the timed test renders (default 16,64,256; --quick 4,16)")
    ap.add_argument("--ref-spp", type=int, help="spp of each reference half, 2 per renderer (default 512; --quick 64)")
    ap.add_argument("--target", type=float, default=0.05, help="relative RMSE whose time is reported")
    ap.add_argument("--max-depth", type=int, default=8, help="host --max-depth (Cycles max_bounces = this - 1, Mitsuba max_depth = this + 1)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1, help="seed base: reference halves seed+1000 and seed+2000, ladder rung k seed+k")
    ap.add_argument("--mitsuba-sampler", default="independent", choices=MITSUBA_SAMPLERS)
    ap.add_argument("--mitsuba-bsdf", default="principled", choices=["principled", "diffuse"], help="Mitsuba's material for glTF's metal-rough: principled (Disney), or diffuse (Lambert) for the non-metals (principled for metals); README: conversion")
    ap.add_argument("--host", default=str(REPO / "target/release/host"), help="the host binary")
    ap.add_argument("--host-args", default="", help='extra `host render` options, appended (e.g. "--sampler sobol")')
    ap.add_argument("--host-test-args", default="", help='extra `host render` options for the ladder only, not the references (e.g. "--adaptive-threshold 0.03": the ladder\'s spp are then each render\'s most)')
    ap.add_argument("--quick", action="store_true", help="smoke test: 64x64, ladder 4,16, references 2 x 64 spp (options given win)")
    ap.add_argument("--report", help="also write the Markdown report here (and its JSON beside it)")
    ap.add_argument("--workdir", help="keep the renders (.npy) here (default: a temporary directory, removed)")
    ap.add_argument("--setup", action="store_true", help=f"create {VENV} with {' '.join(PACKAGES)} and exit")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker_main(args.worker)
    if args.setup:
        return setup_venv()
    for k, full, quick in (("width", 256, 64), ("height", 256, 64), ("ladder", "16,64,256", "4,16"), ("ref_spp", 512, 64)):
        if getattr(args, k) is None:
            setattr(args, k, quick if args.quick else full)
    if min(args.width, args.height) < 1 or args.ref_spp < 1:
        ap.error("--width, --height and --ref-spp must be positive")
    try:
        args.ladder = sorted({int(x) for x in str(args.ladder).split(",")})
    except ValueError:
        ap.error(f"--ladder {args.ladder}: expected comma-separated spp counts such as 16,64,256")
    if args.ladder[0] < 1:
        ap.error("--ladder: spp counts must be positive")
    names = [n.strip() for n in args.renderers.split(",") if n.strip()]
    bad = [n for n in names if n not in RENDERERS]
    if bad:
        ap.error(f"--renderers: unknown {', '.join(bad)}; known: {', '.join(RENDERERS)}")
    if len(args.ladder) < 2:
        ap.error("--ladder: give at least two spp values (the fit needs two points)")
    scene = Path(args.scene).resolve()
    if not scene.exists():
        ap.error(f"--scene {scene}: no such file")
    args.scene = str(scene)
    maybe_reexec(sorted({m for n in ["main", *names] for m in NEEDS.get(n, [])}))
    mach = machine_info()
    log(f"machine: {mach['cpu']}, {mach['cores']} cores; {mach['uptime']}")
    g = Gltf(scene)
    g.camera(0)
    scene_note = "" if g.has_lights else " (no lights of its own: every renderer lights it with a uniform environment of radiance 1)"
    renders = [{"name": "ref1", "spp": args.ref_spp, "seed": args.seed + 1000}, {"name": "ref2", "spp": args.ref_spp, "seed": args.seed + 2000}]
    renders += [{"name": f"spp{n}", "spp": n, "seed": args.seed + k + 1} for k, n in enumerate(args.ladder)]
    tmp = None
    if args.workdir:
        work = Path(args.workdir).resolve()
        work.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.mkdtemp(prefix="peers-")
        work = Path(tmp)
    results, failed, infos = {}, {}, {}
    try:
        for name in names:
            log(f"{name}: {len(renders)} renders ({', '.join(str(r['spp']) for r in renders)} spp) at {args.width}x{args.height}")
            job = {"name": name, "scene": str(scene), "width": args.width, "height": args.height, "threads": args.threads, "max_depth": args.max_depth, "renders": renders, "dir": str(work), "mitsuba_sampler": args.mitsuba_sampler, "mitsuba_bsdf": args.mitsuba_bsdf}
            if name.startswith("mitsuba"):
                job["variant"] = "scalar_rgb" if name == "mitsuba-scalar" else "llvm_ad_rgb"
            t = time.time()
            try:
                info = run_host(args, job, work) if name == "host" else run_worker(name, job, work, args)
            except (RuntimeError, subprocess.SubprocessError, OSError) as e:
                failed[name] = str(e)
                log(f"error: {e}")
                continue
            info["wall_seconds"] = time.time() - t
            infos[name] = info
            results[name] = {**analyse(name, info, work, args), "version": info["version"], "warnings": info.get("warnings", []), "notices": info.get("notices", [])}
        base = results.get("host")
        for name, r in results.items():
            if base is not None and name != "host":
                r["mean_vs_host"], r["blocks_vs_host"] = agreement(base["ref"], r["ref"])
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)
    text = report(args, mach, results, failed, scene_note)
    print(text)
    if args.report:
        rp = Path(args.report)
        rp.parent.mkdir(parents=True, exist_ok=True)
        rp.write_text(text)
        out = {"machine": mach, "settings": {k: v for k, v in vars(args).items() if k not in ("worker", "setup")}, "scene_has_lights": g.has_lights, "failed": failed}
        out["renderers"] = {n: {**{k: v for k, v in r.items() if k != "ref"}, "info": infos[n]} for n, r in results.items()}
        rp.with_suffix(".json").write_text(json.dumps(out, indent=2) + "\n")
        log(f"wrote {rp} and {rp.with_suffix('.json')}")
    if failed:
        sys.exit(1)


if __name__ == "__main__":
    main()
