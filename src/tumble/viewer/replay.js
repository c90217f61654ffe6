/* tumble replay: WebGL renderer, orbit camera, playback, picking and the energy plot. No dependencies.
 *
 * Data (the JSON block "tumble-data", written by tumble/viewer/page.py): arrays are blobs
 * {dtype, shape, gzip, data} in little-endian base64. Moving bodies have per-frame poses, body-major
 * (pos: M x T x 3 float32, quat: M x T x 4 int16 = round(32767 q), q = [w, x, y, z]); the other bodies stay
 * at restPos / restQuat. Shapes are in their body's frame (from the body frame's origin).
 *
 * Drawing: one draw call per kind of mesh (box, sphere, capsule, cylinder, each hull or mesh, planes) with
 * instancing (WebGL2, or WebGL1 + ANGLE_instanced_arrays). Each instance carries its shape's pose in the body
 * frame, its size and colour (static), and its body's pose at the shown time (updated per frame); the vertex
 * shader composes them. Unit meshes use aPos.w for capsules: p = aPos.xyz * size.xyz + (0, 0, aPos.w * size.w).
 */
(function () {
  "use strict";

  const $ = (id) => document.getElementById(id);
  const api = { ready: false, error: null, drawCount: 0 };
  window.tumbleReplay = api;

  function fail(message) {
    api.error = String(message);
    const box = $("message");
    box.textContent = String(message);
    box.hidden = false;
  }

  // ---------------------------------------------------------------------------------------------- decoding

  function base64Bytes(text) {
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    return bytes;
  }

  async function inflate(bytes) {
    if (typeof DecompressionStream === "undefined") {
      throw new Error("This browser cannot inflate the compressed data (no DecompressionStream). " +
        "Write the page with compress=False.");
    }
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  function halfToFloat(h) {
    const sign = h & 0x8000 ? -1 : 1;
    const exponent = (h >> 10) & 0x1f;
    const fraction = h & 0x3ff;
    if (exponent === 0) return sign * fraction * Math.pow(2, -24);
    if (exponent === 31) return fraction ? NaN : sign * Infinity;
    return sign * (1 + fraction / 1024) * Math.pow(2, exponent - 15);
  }

  async function decode(blob) {
    let bytes = base64Bytes(blob.data);
    if (blob.gzip) bytes = await inflate(bytes);
    const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
    switch (blob.dtype) {
      case "f4": return new Float32Array(buffer);
      case "f8": return new Float64Array(buffer);
      case "i2": return new Int16Array(buffer);
      case "i4": return new Int32Array(buffer);
      case "u4": return new Uint32Array(buffer);
      case "f2": {
        const half = new Uint16Array(buffer);
        const out = new Float32Array(half.length);
        for (let i = 0; i < half.length; i++) out[i] = halfToFloat(half[i]);
        return out;
      }
      default: throw new Error("unknown dtype " + blob.dtype);
    }
  }

  // ---------------------------------------------------------------------------------------------- maths
  // Matrices are column-major Float32Array(16), as WebGL wants them.

  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    const m = new Float32Array(16);
    m[0] = f / aspect; m[5] = f; m[10] = (far + near) * nf; m[11] = -1; m[14] = 2 * far * near * nf;
    return m;
  }

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function normalize(a) { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }

  function lookAt(eye, target, up) {
    const f = normalize(sub(target, eye));
    const s = normalize(cross(f, up));
    const u = cross(s, f);
    const m = new Float32Array(16);
    m[0] = s[0]; m[4] = s[1]; m[8] = s[2];
    m[1] = u[0]; m[5] = u[1]; m[9] = u[2];
    m[2] = -f[0]; m[6] = -f[1]; m[10] = -f[2];
    m[12] = -dot(s, eye); m[13] = -dot(u, eye); m[14] = dot(f, eye); m[15] = 1;
    return m;
  }

  function multiply(a, b) {
    const m = new Float32Array(16);
    for (let c = 0; c < 4; c++) {
      for (let r = 0; r < 4; r++) {
        m[c * 4 + r] = a[r] * b[c * 4] + a[4 + r] * b[c * 4 + 1] + a[8 + r] * b[c * 4 + 2] + a[12 + r] * b[c * 4 + 3];
      }
    }
    return m;
  }

  function transform(m, p) {
    const x = p[0], y = p[1], z = p[2];
    return [m[0] * x + m[4] * y + m[8] * z + m[12], m[1] * x + m[5] * y + m[9] * z + m[13],
      m[2] * x + m[6] * y + m[10] * z + m[14], m[3] * x + m[7] * y + m[11] * z + m[15]];
  }

  // q = [w, x, y, z]: v' = v + 2 u x (u x v + w v), u = (x, y, z).
  function quatRotate(q, v) {
    const ux = q[1], uy = q[2], uz = q[3], w = q[0];
    const tx = uy * v[2] - uz * v[1] + w * v[0];
    const ty = uz * v[0] - ux * v[2] + w * v[1];
    const tz = ux * v[1] - uy * v[0] + w * v[2];
    return [v[0] + 2 * (uy * tz - uz * ty), v[1] + 2 * (uz * tx - ux * tz), v[2] + 2 * (ux * ty - uy * tx)];
  }

  // ---------------------------------------------------------------------------------------------- unit meshes
  // Interleaved vertices [px, py, pz, pw, nx, ny, nz], triangles counter-clockwise seen from outside.

  function pushQuad(out, a, b, c, d) { out.push(...a, ...b, ...c, ...a, ...c, ...d); }

  function boxMesh() {
    const out = [];
    const faces = [ // normal, u, v with u x v = normal
      [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]],
      [[0, 1, 0], [0, 0, 1], [1, 0, 0]], [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
      [[0, 0, 1], [1, 0, 0], [0, 1, 0]], [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
    ];
    for (const [n, u, v] of faces) {
      const corner = (su, sv) => [n[0] + su * u[0] + sv * v[0], n[1] + su * u[1] + sv * v[1],
        n[2] + su * u[2] + sv * v[2], 0, ...n];
      pushQuad(out, corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1));
    }
    return out;
  }

  // A UV sphere; with capsule=true its upper half is shifted by +half (w = 1), its lower by -half (w = -1),
  // and a band joins them.
  function sphereMesh(segments, rings, capsule) {
    const out = [];
    const vertex = (i, j, w) => {
      const theta = Math.PI * i / rings, phi = 2 * Math.PI * j / segments;
      const n = [Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta)];
      return [n[0], n[1], n[2], w, n[0], n[1], n[2]];
    };
    for (let i = 0; i < rings; i++) {
      const w = capsule ? (i < rings / 2 ? 1 : -1) : 0;
      for (let j = 0; j < segments; j++) {
        // (i, j) is up-left seen from outside: theta grows downwards, phi to the right.
        pushQuad(out, vertex(i + 1, j, w), vertex(i + 1, j + 1, w), vertex(i, j + 1, w), vertex(i, j, w));
      }
    }
    if (capsule) {
      const e = rings / 2;
      for (let j = 0; j < segments; j++) {
        pushQuad(out, vertex(e, j, -1), vertex(e, j + 1, -1), vertex(e, j + 1, 1), vertex(e, j, 1));
      }
    }
    return out;
  }

  function cylinderMesh(segments) {
    const out = [];
    const ring = (j) => { const a = 2 * Math.PI * j / segments; return [Math.cos(a), Math.sin(a)]; };
    for (let j = 0; j < segments; j++) {
      const [x0, y0] = ring(j), [x1, y1] = ring(j + 1);
      pushQuad(out, [x0, y0, -1, 0, x0, y0, 0], [x1, y1, -1, 0, x1, y1, 0],
        [x1, y1, 1, 0, x1, y1, 0], [x0, y0, 1, 0, x0, y0, 0]);
      out.push(0, 0, 1, 0, 0, 0, 1, x0, y0, 1, 0, 0, 0, 1, x1, y1, 1, 0, 0, 0, 1);
      out.push(0, 0, -1, 0, 0, 0, -1, x1, y1, -1, 0, 0, 0, -1, x0, y0, -1, 0, 0, 0, -1);
    }
    return out;
  }

  function planeMesh() {
    const out = [];
    pushQuad(out, [-1, -1, 0, 0, 0, 0, 1], [1, -1, 0, 0, 0, 0, 1], [1, 1, 0, 0, 0, 0, 1], [-1, 1, 0, 0, 0, 0, 1]);
    return out;
  }

  // Hulls and meshes: flat shading, so each triangle gets its own three vertices and its face normal.
  function triangleMesh(vertices, faces) {
    const out = new Float32Array(faces.length * 7);
    for (let f = 0; f < faces.length; f += 3) {
      const a = faces[f] * 3, b = faces[f + 1] * 3, c = faces[f + 2] * 3;
      const pa = [vertices[a], vertices[a + 1], vertices[a + 2]];
      const pb = [vertices[b], vertices[b + 1], vertices[b + 2]];
      const pc = [vertices[c], vertices[c + 1], vertices[c + 2]];
      const n = normalize(cross(sub(pb, pa), sub(pc, pa)));
      [pa, pb, pc].forEach((p, k) => out.set([p[0], p[1], p[2], 0, n[0], n[1], n[2]], (f + k) * 7));
    }
    return out;
  }

  // ---------------------------------------------------------------------------------------------- shaders

  const VERTEX_SHADER = `
attribute vec4 aPos;
attribute vec3 aNormal;
attribute vec3 aShapePos;
attribute vec4 aShapeQuat;
attribute vec4 aScale;
attribute vec4 aColor;
attribute vec3 aBodyPos;
attribute vec4 aBodyQuat;
uniform mat4 uViewProj;
uniform float uSelected;
varying vec3 vNormal;
varying vec3 vColor;
varying vec3 vPick;
varying vec2 vGrid;
varying float vSelected;
vec3 qrot(vec4 q, vec3 v) { vec3 u = q.yzw; return v + 2.0 * cross(u, cross(u, v) + q.x * v); }
void main() {
  vec3 p = aPos.xyz * aScale.xyz + vec3(0.0, 0.0, aPos.w * aScale.w);
  vec3 n = aNormal / aScale.xyz;
  p = qrot(aBodyQuat, qrot(aShapeQuat, p) + aShapePos) + aBodyPos;
  vNormal = qrot(aBodyQuat, qrot(aShapeQuat, n));
  vColor = aColor.rgb;
  vGrid = aPos.xy * aScale.xy;
  float id = aColor.a + 1.0;
  vPick = vec3(mod(id, 256.0), mod(floor(id / 256.0), 256.0), floor(id / 65536.0)) / 255.0;
  vSelected = abs(aColor.a - uSelected) < 0.5 ? 1.0 : 0.0;
  gl_Position = uViewProj * vec4(p, 1.0);
}`;

  const FRAGMENT_SHADER = `
#ifdef GL_FRAGMENT_PRECISION_HIGH
precision highp float;
#else
precision mediump float;
#endif
uniform float uPick;
uniform float uGrid;
uniform vec3 uLight;
varying vec3 vNormal;
varying vec3 vColor;
varying vec3 vPick;
varying vec2 vGrid;
varying float vSelected;
void main() {
  if (uPick > 0.5) { gl_FragColor = vec4(vPick, 1.0); return; }
  vec3 n = normalize(vNormal);
  if (!gl_FrontFacing) n = -n;
  vec3 base = vColor;
  if (uGrid > 0.0) {
    float checker = mod(floor(vGrid.x / uGrid) + floor(vGrid.y / uGrid), 2.0);
    base *= 0.9 + 0.1 * checker;
  }
  base = mix(base, vec3(1.0, 0.85, 0.2), 0.75 * vSelected);
  float diffuse = max(dot(n, uLight), 0.0);
  float sky = 0.5 + 0.5 * n.z;
  vec3 color = base * (0.28 + 0.22 * sky + 0.6 * diffuse) + 0.15 * vSelected;
  gl_FragColor = vec4(color, 1.0);
}`;

  function compile(gl, type, source) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error("shader: " + gl.getShaderInfoLog(shader));
    return shader;
  }

  function makeProgram(gl) {
    const program = gl.createProgram();
    gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX_SHADER));
    gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT_SHADER));
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error("program: " + gl.getProgramInfoLog(program));
    const attrib = {}, uniform = {};
    for (const name of ["aPos", "aNormal", "aShapePos", "aShapeQuat", "aScale", "aColor", "aBodyPos", "aBodyQuat"]) {
      attrib[name] = gl.getAttribLocation(program, name);
    }
    for (const name of ["uViewProj", "uSelected", "uPick", "uGrid", "uLight"]) {
      uniform[name] = gl.getUniformLocation(program, name);
    }
    return { program, attrib, uniform };
  }

  // ---------------------------------------------------------------------------------------------- colours

  function bodyColor(index) {
    // Golden-ratio hues: neighbouring indices get well separated colours.
    const h = (index * 0.61803398875 + 0.12) % 1, s = 0.5, l = 0.56;
    const k = (n) => (n + h * 12) % 12;
    const a = s * Math.min(l, 1 - l);
    const f = (n) => l - a * Math.max(-1, Math.min(k(n) - 3, Math.min(9 - k(n), 1)));
    return [f(0), f(8), f(4)];
  }
  const STATIC_COLOR = [0.6, 0.63, 0.68];
  const PLANE_COLOR = [0.8, 0.82, 0.85];
  const PATH_COLOR = [0.85, 0.25, 0.2];
  const BLADE_COLOR = [0.15, 0.15, 0.18];

  function softwareRenderer() {
    try {
      const probe = document.createElement("canvas").getContext("webgl");
      const ext = probe && probe.getExtension("WEBGL_debug_renderer_info");
      const name = ext ? String(probe.getParameter(ext.UNMASKED_RENDERER_WEBGL)) : "";
      const lose = probe && probe.getExtension("WEBGL_lose_context");
      if (lose) lose.loseContext();
      return /swiftshader|llvmpipe|softpipe|software/i.test(name);
    } catch (error) {
      return false;
    }
  }

  // ---------------------------------------------------------------------------------------------- the replay

  async function main() {
    const data = JSON.parse($("tumble-data").textContent);
    const [time, kinetic, potential, restPos, restQuat, moving, pos, quat, speed] = await Promise.all(
      ["time", "kinetic", "potential", "restPos", "restQuat", "moving", "pos", "quat", "speed"].map((k) => decode(data[k])));
    const meshes = await Promise.all(data.meshes.map(async (m) => ({
      vertices: await decode(m.vertices), faces: await decode(m.faces) })));
    // Quadrotors: their reference paths (world points) and their blades (an angle per frame).
    const paths = await Promise.all((data.paths || []).map(async (p) => ({ body: p.body, points: await decode(p.points) })));
    const rotors = await Promise.all((data.rotors || []).map(async (r) => ({ ...r, angles: await decode(r.angles) })));
    const N = data.bodyCount, T = data.frameCount;
    const slot = new Int32Array(N).fill(-1);
    moving.forEach((body, m) => { slot[body] = m; });
    const t0 = time[0], t1 = time[T - 1], duration = t1 - t0;

    // --- GL context, with instancing from WebGL2 or ANGLE_instanced_arrays
    const canvas = $("scene");
    // Multisampling is nearly free on a GPU but costs a software rasteriser (SwiftShader, llvmpipe) much of
    // its frame rate, so it is turned off there.
    const software = softwareRenderer();
    const options = { antialias: !software, preserveDrawingBuffer: true, alpha: false };
    let gl = canvas.getContext("webgl2", options), divisor, drawInstanced;
    if (gl) {
      divisor = (loc, d) => gl.vertexAttribDivisor(loc, d);
      drawInstanced = (count, instances) => gl.drawArraysInstanced(gl.TRIANGLES, 0, count, instances);
    } else {
      gl = canvas.getContext("webgl", options) || canvas.getContext("experimental-webgl", options);
      const ext = gl && gl.getExtension("ANGLE_instanced_arrays");
      if (!ext) throw new Error("This browser has no WebGL with instancing; the replay cannot be drawn.");
      divisor = (loc, d) => ext.vertexAttribDivisorANGLE(loc, d);
      drawInstanced = (count, instances) => ext.drawArraysInstancedANGLE(gl.TRIANGLES, 0, count, instances);
    }
    api.renderer = { webgl2: typeof WebGL2RenderingContext !== "undefined" && gl instanceof WebGL2RenderingContext,
      software, antialias: options.antialias };
    const prog = makeProgram(gl);
    gl.useProgram(prog.program);
    for (const name of ["aShapePos", "aShapeQuat", "aScale", "aColor", "aBodyPos", "aBodyQuat"]) {
      if (prog.attrib[name] >= 0) divisor(prog.attrib[name], 1);
    }
    for (const loc of Object.values(prog.attrib)) if (loc >= 0) gl.enableVertexAttribArray(loc);

    // --- batches: one per mesh, holding its instances
    const unit = {
      box: { vertices: boxMesh(), cull: true },
      sphere: { vertices: sphereMesh(20, 10, false), cull: true },
      capsule: { vertices: sphereMesh(20, 10, true), cull: true },
      cylinder: { vertices: cylinderMesh(24), cull: true },
      plane: { vertices: planeMesh(), cull: false },
    };
    const batches = new Map();
    function batchFor(key, make) {
      if (!batches.has(key)) {
        const mesh = make();
        const buffer = gl.createBuffer();
        const vertices = mesh.vertices instanceof Float32Array ? mesh.vertices : new Float32Array(mesh.vertices);
        gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
        gl.bufferData(gl.ARRAY_BUFFER, vertices, gl.STATIC_DRAW);
        batches.set(key, { buffer, vertexCount: vertices.length / 7, cull: mesh.cull, grid: mesh.grid || 0,
          instances: [] });
      }
      return batches.get(key);
    }
    const bodyShapes = Array.from({ length: N }, () => []);
    for (const shape of data.shapes) {
      const s = shape.size, kind = shape.kind;
      let batch, scale;
      if (kind === "box") { batch = batchFor("box", () => unit.box); scale = [s[0], s[1], s[2], 0]; }
      else if (kind === "sphere") { batch = batchFor("sphere", () => unit.sphere); scale = [s[0], s[0], s[0], 0]; }
      else if (kind === "capsule") { batch = batchFor("capsule", () => unit.capsule); scale = [s[0], s[0], s[0], s[1]]; }
      else if (kind === "cylinder") { batch = batchFor("cylinder", () => unit.cylinder); scale = [s[0], s[0], s[1], 0]; }
      else {
        const m = meshes[shape.mesh];
        batch = batchFor("mesh" + shape.mesh, () => ({ vertices: triangleMesh(m.vertices, m.faces), cull: kind === "hull" }));
        scale = [1, 1, 1, 0];
      }
      const color = data.mass[shape.body] > 0 ? bodyColor(shape.body) : STATIC_COLOR;
      batch.instances.push({ body: shape.body, world: false, pose: [...shape.position, ...shape.quat], scale, color });
      bodyShapes[shape.body].push(shape.position);
    }
    const diagonal = Math.hypot(...sub(data.bounds.max, data.bounds.min)) || 1;
    const viewSize = Math.hypot(...sub(data.view.max, data.view.min)) || diagonal;
    const gridSize = Math.pow(10, Math.round(Math.log10(viewSize / 8)));
    for (const plane of data.planes) {
      const batch = batchFor("plane", () => ({ ...unit.plane, grid: gridSize }));
      batch.instances.push({ body: plane.body, world: true, pose: [...plane.center, ...plane.quat],
        scale: [plane.half, plane.half, 1, 0], color: PLANE_COLOR });
    }
    // A reference path: thin bars from point to point, fixed in the world (picking one picks its vehicle).
    const pathWidth = 0.002 * viewSize;
    for (const path of paths) {
      const batch = batchFor("box", () => unit.box), p = path.points;
      for (let k = 0; k + 5 < p.length; k += 3) {
        const a = [p[k], p[k + 1], p[k + 2]], d = [p[k + 3] - a[0], p[k + 4] - a[1], p[k + 5] - a[2]];
        const length = Math.hypot(d[0], d[1], d[2]);
        if (!(length > 0)) continue;
        // The rotation taking x onto d: axis x × d, half the angle (a half turn about z when d is -x).
        const w = 1 + d[0] / length, q = w > 1e-9 ? [w, 0, -d[2] / length, d[1] / length] : [0, 0, 0, 1];
        const qn = Math.hypot(...q);
        batch.instances.push({ body: path.body, world: true,
          pose: [a[0] + 0.5 * d[0], a[1] + 0.5 * d[1], a[2] + 0.5 * d[2], ...q.map((v) => v / qn)],
          scale: [0.5 * length, pathWidth, pathWidth, 0], color: PATH_COLOR });
      }
    }
    // A blade over each rotor disc, turned about the body's z at its hub by the rotor's angle (updatePoses).
    rotors.forEach((rotor, k) => {
      batchFor("box", () => unit.box).instances.push({ body: rotor.body, world: false, spin: k,
        pose: [...rotor.hub, 1, 0, 0, 0], scale: [rotor.radius, 0.12 * rotor.radius, 0.02 * rotor.radius, 0],
        color: BLADE_COLOR });
    });
    // Per-instance buffers: static [shape pos 3, shape quat 4, scale 4, colour 3 + body id] and
    // dynamic [body pos 3, body quat 4] (rewritten whenever the shown time changes).
    for (const batch of batches.values()) {
      const n = batch.instances.length;
      const fixed = new Float32Array(n * 15);
      batch.instances.forEach((inst, k) => fixed.set([...inst.pose, ...inst.scale, ...inst.color, inst.body], k * 15));
      batch.fixed = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, batch.fixed);
      gl.bufferData(gl.ARRAY_BUFFER, fixed, gl.STATIC_DRAW);
      batch.poses = new Float32Array(n * 7);
      batch.dynamic = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, batch.dynamic);
      gl.bufferData(gl.ARRAY_BUFFER, batch.poses, gl.DYNAMIC_DRAW);
    }
    api.batches = Object.fromEntries(Array.from(batches, ([key, batch]) => [key, batch.instances.length]));
    // The centre of each body's shapes in its frame: what project() aims at.
    const bodyCentre = bodyShapes.map((list) => list.length === 0 ? [0, 0, 0]
      : [0, 1, 2].map((k) => list.reduce((acc, p) => acc + p[k], 0) / list.length));

    // --- state
    const S = { time: t0, playing: false, speed: 1, loop: true, selected: -1, dirty: true, frame: 0, alpha: 0 };
    // The camera first frames where the bodies spend most of the run (data.view), seen from the front left.
    const centre = [0, 1, 2].map((k) => 0.5 * (data.view.min[k] + data.view.max[k]));
    const camera = { target: centre.slice(), yaw: -Math.PI / 4 - 0.3, pitch: 0.5, distance: 1.05 * viewSize,
      fovy: Math.PI / 4 };
    const home = { ...camera, target: centre.slice() };
    const poses = new Float32Array(N * 7);
    let viewProj = new Float32Array(16);

    function locate(t) {
      // The frame f with time[f] <= t < time[f + 1] (binary search), and where t falls in it.
      let lo = 0, hi = T - 1;
      if (t <= time[0]) return [0, 0];
      if (t >= time[T - 1]) return [T - 1, 0];
      while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (time[mid] <= t) lo = mid; else hi = mid; }
      const span = time[hi] - time[lo];
      return [lo, span > 0 ? (t - time[lo]) / span : 0];
    }

    function updatePoses() {
      const [f, a] = locate(S.time);
      S.frame = a < 0.5 ? f : Math.min(f + 1, T - 1);
      S.alpha = a;
      const g = Math.min(f + 1, T - 1);
      for (let b = 0; b < N; b++) {
        const m = slot[b], o = b * 7;
        if (m < 0) {
          poses.set(restPos.subarray(b * 3, b * 3 + 3), o);
          poses.set(restQuat.subarray(b * 4, b * 4 + 4), o + 3);
          continue;
        }
        const p0 = (m * T + f) * 3, p1 = (m * T + g) * 3, q0 = (m * T + f) * 4, q1 = (m * T + g) * 4;
        for (let k = 0; k < 3; k++) poses[o + k] = pos[p0 + k] + a * (pos[p1 + k] - pos[p0 + k]);
        // nlerp along the shorter arc (q and -q are the same rotation).
        let d = 0;
        for (let k = 0; k < 4; k++) d += quat[q0 + k] * quat[q1 + k];
        const s1 = d < 0 ? -a : a;
        let norm = 0;
        for (let k = 0; k < 4; k++) {
          const v = (1 - a) * quat[q0 + k] + s1 * quat[q1 + k];
          poses[o + 3 + k] = v;
          norm += v * v;
        }
        norm = Math.sqrt(norm) || 1;
        for (let k = 0; k < 4; k++) poses[o + 3 + k] /= norm;
      }
      for (const batch of batches.values()) {
        batch.instances.forEach((inst, k) => {
          if (inst.spin !== undefined) batch.poses.set(bladePose(inst.body, rotors[inst.spin], f, g, a), k * 7);
          else if (inst.world) batch.poses.set([0, 0, 0, 1, 0, 0, 0], k * 7);
          else batch.poses.set(poses.subarray(inst.body * 7, inst.body * 7 + 7), k * 7);
        });
        gl.bindBuffer(gl.ARRAY_BUFFER, batch.dynamic);
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, batch.poses);
      }
    }

    // The pose that turns a blade placed at ``hub`` (in its body's frame) by its angle about the body's z at the
    // hub: the body's pose composed with the turn R_z(θ) about the hub, p = x_b + R_b (h - R_z h), q = q_b ⊗ q_z.
    function bladePose(body, rotor, f, g, a) {
      const theta = rotor.angles[f] + a * (rotor.angles[g] - rotor.angles[f]);
      const c = Math.cos(theta), s = Math.sin(theta), h = rotor.hub;
      const b = poses.subarray(body * 7, body * 7 + 7), bq = [b[3], b[4], b[5], b[6]];
      const shift = quatRotate(bq, [h[0] - (c * h[0] - s * h[1]), h[1] - (s * h[0] + c * h[1]), 0]);
      const hw = Math.cos(theta / 2), hz = Math.sin(theta / 2);
      return [b[0] + shift[0], b[1] + shift[1], b[2] + shift[2],
        bq[0] * hw - bq[3] * hz, bq[1] * hw + bq[2] * hz, bq[2] * hw - bq[1] * hz, bq[3] * hw + bq[0] * hz];
    }

    function eye() {
      const c = Math.cos(camera.pitch);
      return [camera.target[0] + camera.distance * c * Math.cos(camera.yaw),
        camera.target[1] + camera.distance * c * Math.sin(camera.yaw),
        camera.target[2] + camera.distance * Math.sin(camera.pitch)];
    }

    function resize() {
      const dpr = window.devicePixelRatio || 1;
      const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
      if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; S.dirty = true; }
    }

    function drawBatches(pick) {
      gl.uniform1f(prog.uniform.uPick, pick ? 1 : 0);
      const a = prog.attrib;
      for (const batch of batches.values()) {
        if (batch.instances.length === 0) continue;
        if (batch.cull) gl.enable(gl.CULL_FACE); else gl.disable(gl.CULL_FACE);
        gl.uniform1f(prog.uniform.uGrid, batch.grid);
        gl.bindBuffer(gl.ARRAY_BUFFER, batch.buffer);
        gl.vertexAttribPointer(a.aPos, 4, gl.FLOAT, false, 28, 0);
        gl.vertexAttribPointer(a.aNormal, 3, gl.FLOAT, false, 28, 16);
        gl.bindBuffer(gl.ARRAY_BUFFER, batch.fixed);
        gl.vertexAttribPointer(a.aShapePos, 3, gl.FLOAT, false, 60, 0);
        gl.vertexAttribPointer(a.aShapeQuat, 4, gl.FLOAT, false, 60, 12);
        gl.vertexAttribPointer(a.aScale, 4, gl.FLOAT, false, 60, 28);
        gl.vertexAttribPointer(a.aColor, 4, gl.FLOAT, false, 60, 44);
        gl.bindBuffer(gl.ARRAY_BUFFER, batch.dynamic);
        gl.vertexAttribPointer(a.aBodyPos, 3, gl.FLOAT, false, 28, 0);
        gl.vertexAttribPointer(a.aBodyQuat, 4, gl.FLOAT, false, 28, 12);
        drawInstanced(batch.vertexCount, batch.instances.length);
      }
    }

    function setupView() {
      const e = eye();
      const aspect = canvas.width / Math.max(1, canvas.height);
      const near = Math.max(camera.distance * 0.01, 1e-4), far = camera.distance * 20 + diagonal * 8;
      viewProj = multiply(perspective(camera.fovy, aspect, near, far), lookAt(e, camera.target, [0, 0, 1]));
      gl.useProgram(prog.program);
      gl.uniformMatrix4fv(prog.uniform.uViewProj, false, viewProj);
      gl.uniform1f(prog.uniform.uSelected, S.selected);
      // A light from above and over the viewer's shoulder.
      const back = normalize(sub(e, camera.target));
      gl.uniform3fv(prog.uniform.uLight, normalize([back[0] * 0.6, back[1] * 0.6, back[2] * 0.6 + 0.8]));
      gl.enable(gl.DEPTH_TEST);
      gl.cullFace(gl.BACK);
    }

    function draw() {
      resize();
      updatePoses();
      setupView();
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.clearColor(0.875, 0.894, 0.918, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      drawBatches(false);
      api.drawCount++;
      updateLabels();
      drawPlot();
    }

    // --- picking: draw body ids into an offscreen buffer, one pixel only (scissor), and read it back
    let pickTarget = null;
    function pickAt(clientX, clientY) {
      const rect = canvas.getBoundingClientRect();
      const px = Math.floor((clientX - rect.left) * canvas.width / rect.width);
      const py = canvas.height - 1 - Math.floor((clientY - rect.top) * canvas.height / rect.height);
      if (px < 0 || py < 0 || px >= canvas.width || py >= canvas.height) return -1;
      if (!pickTarget || pickTarget.w !== canvas.width || pickTarget.h !== canvas.height) {
        if (pickTarget) { gl.deleteFramebuffer(pickTarget.fb); gl.deleteTexture(pickTarget.tex); gl.deleteRenderbuffer(pickTarget.depth); }
        const tex = gl.createTexture();
        gl.bindTexture(gl.TEXTURE_2D, tex);
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, canvas.width, canvas.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
        const depth = gl.createRenderbuffer();
        gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT16, canvas.width, canvas.height);
        const fb = gl.createFramebuffer();
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
        pickTarget = { fb, tex, depth, w: canvas.width, h: canvas.height };
      }
      updatePoses();
      setupView();
      gl.bindFramebuffer(gl.FRAMEBUFFER, pickTarget.fb);
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.enable(gl.SCISSOR_TEST);
      gl.scissor(px, py, 1, 1);
      gl.clearColor(0, 0, 0, 0);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      drawBatches(true);
      const pixel = new Uint8Array(4);
      gl.readPixels(px, py, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      gl.disable(gl.SCISSOR_TEST);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      return pixel[0] + 256 * pixel[1] + 65536 * pixel[2] - 1;
    }

    function project(body) {
      updatePoses();
      setupView();
      const o = body * 7;
      const q = [poses[o + 3], poses[o + 4], poses[o + 5], poses[o + 6]];
      const local = quatRotate(q, bodyCentre[body]);
      const p = transform(viewProj, [poses[o] + local[0], poses[o + 1] + local[1], poses[o + 2] + local[2]]);
      const rect = canvas.getBoundingClientRect();
      const x = rect.left + (p[0] / p[3] * 0.5 + 0.5) * rect.width;
      const y = rect.top + (0.5 - p[1] / p[3] * 0.5) * rect.height;
      const visible = p[3] > 0 && x >= rect.left && x < rect.right && y >= rect.top && y < rect.bottom;
      return { x, y, depth: p[3], visible };
    }

    // --- labels: time, HUD, picked body
    const slider = $("slider"), timeLabel = $("time"), info = $("info"), hud = $("hud"), playButton = $("play");
    slider.min = String(t0);
    slider.max = String(duration > 0 ? t1 : t0 + 1);
    // Four significant digits, without trailing zeros; exponent form when large or tiny.
    const fmt = (v, digits) => v === 0 ? "0" : (Math.abs(v) >= 1e5 || Math.abs(v) < 1e-3) ? v.toExponential(digits - 1)
      : String(Number(v.toPrecision(digits)));
    const escapeText = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
    let fps = 0;

    function updateLabels() {
      timeLabel.textContent = `t = ${S.time.toFixed(3)} s / ${t1.toFixed(3)} s · frame ${S.frame + 1}/${T}`;
      if (document.activeElement !== slider) slider.value = String(S.time);
      const symbol = S.playing ? "\u275a\u275a" : "\u25b6";
      if (playButton.textContent !== symbol) playButton.textContent = symbol;
      hud.textContent = `${N} bodies · ${moving.length} moving · ${T} frames` + (S.playing ? ` · ${fps.toFixed(0)} fps` : "");
      if (S.selected < 0) { info.hidden = true; return; }
      const b = S.selected, m = slot[b];
      let v = 0;
      if (m >= 0) {
        const i0 = m * T + Math.min(S.frame, T - 1);
        v = speed[i0];
      }
      const o = b * 7;
      const mass = data.mass[b];
      info.innerHTML = `<div class="name">${escapeText(data.names[b])}</div><table>` +
        `<tr><td>body</td><td>#${b}</td></tr>` +
        `<tr><td>mass</td><td>${mass > 0 ? fmt(mass, 4) + " kg" : "static"}</td></tr>` +
        `<tr><td>speed</td><td>${fmt(v, 4)} m/s</td></tr>` +
        `<tr><td>position</td><td>${poses[o].toFixed(3)}, ${poses[o + 1].toFixed(3)}, ${poses[o + 2].toFixed(3)} m</td></tr>` +
        "</table>";
      info.hidden = false;
    }

    function select(body) {
      S.selected = body >= 0 && body < N ? body : -1;
      S.dirty = true;
    }

    // --- energy plot
    const plot = $("energy");
    const pctx = plot.getContext("2d");
    let plotBase = null, plotFrame = null;
    const SERIES = [["kinetic", "#d9682b"], ["potential", "#2f6db5"], ["total", "#222"]];
    const total = new Float32Array(T);
    for (let f = 0; f < T; f++) total[f] = kinetic[f] + potential[f];
    const values = { kinetic, potential, total };

    function niceStep(range, count) {
      const raw = range / Math.max(1, count), p = Math.pow(10, Math.floor(Math.log10(raw)));
      const r = raw / p;
      return (r < 1.5 ? 1 : r < 3.5 ? 2 : r < 7.5 ? 5 : 10) * p;
    }

    // Tick values with as many decimals as the step needs (no "2000.000 J"); exponent form on axes that reach
    // 1e5 or stay under 1e-3.
    function tickLabel(value, step, top) {
      if (Math.abs(value) < step * 1e-6) return "0";
      if (top >= 1e5 || top < 1e-3) return value.toExponential(Math.max(0, Math.ceil(Math.log10(top / step) - 1e-9)));
      return value.toFixed(Math.max(0, -Math.floor(Math.log10(step) + 1e-9)));
    }

    function buildPlot() {
      const dpr = window.devicePixelRatio || 1;
      const w = Math.max(1, Math.round(plot.clientWidth * dpr)), h = Math.max(1, Math.round(plot.clientHeight * dpr));
      plot.width = w; plot.height = h;
      const base = document.createElement("canvas");
      base.width = w; base.height = h;
      const ctx = base.getContext("2d");
      ctx.scale(dpr, dpr);
      const W = w / dpr, H = h / dpr, left = 64, right = 12, top = 20, bottom = 22;
      let lo = Infinity, hi = -Infinity;
      for (const [name] of SERIES) for (const v of values[name]) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
      if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { lo -= 1; hi += 1; }
      const pad = 0.06 * (hi - lo); lo -= pad; hi += pad;
      const span = duration > 0 ? duration : 1;
      const X = (t) => left + (t - t0) / span * (W - left - right);
      const Y = (e) => top + (hi - e) / (hi - lo) * (H - top - bottom);
      ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, W, H);
      ctx.font = "11px system-ui, sans-serif"; ctx.fillStyle = "#5b6475"; ctx.strokeStyle = "#e3e6eb"; ctx.lineWidth = 1;
      const ey = niceStep(hi - lo, 4);
      ctx.textAlign = "right"; ctx.textBaseline = "middle";
      for (let e = Math.ceil(lo / ey) * ey; e <= hi; e += ey) {
        ctx.beginPath(); ctx.moveTo(left, Y(e)); ctx.lineTo(W - right, Y(e)); ctx.stroke();
        ctx.fillText(tickLabel(e, ey, Math.max(Math.abs(lo), Math.abs(hi))) + " J", left - 6, Y(e));
      }
      const tx = niceStep(span, 8);
      ctx.textAlign = "center"; ctx.textBaseline = "top";
      for (let t = Math.ceil(t0 / tx) * tx; t <= t0 + span + 1e-9; t += tx) {
        ctx.beginPath(); ctx.moveTo(X(t), top); ctx.lineTo(X(t), H - bottom); ctx.stroke();
        ctx.fillText(tickLabel(t, tx, Math.max(Math.abs(t0), Math.abs(t0 + span))) + " s", X(t), H - bottom + 4);
      }
      ctx.strokeStyle = "#9aa3b1"; ctx.strokeRect(left, top, W - left - right, H - top - bottom);
      ctx.lineWidth = 1.5;
      let lx = left + 4;
      for (const [name, color] of SERIES) {
        const v = values[name];
        ctx.strokeStyle = color; ctx.beginPath();
        let pen = false;
        for (let f = 0; f < T; f++) {
          if (!Number.isFinite(v[f])) { pen = false; continue; }
          if (pen) ctx.lineTo(X(time[f]), Y(v[f])); else ctx.moveTo(X(time[f]), Y(v[f]));
          pen = true;
        }
        ctx.stroke();
        ctx.fillStyle = color; ctx.textAlign = "left"; ctx.textBaseline = "top";
        ctx.fillRect(lx, 6, 14, 3);
        ctx.fillText(name, lx + 18, 1);
        lx += 26 + ctx.measureText(name).width;
      }
      plotBase = base;
      plotFrame = { X, Y, left, right, top, bottom, W, H, dpr };
    }

    function drawPlot() {
      if (!plotBase || plotBase.width !== Math.max(1, Math.round(plot.clientWidth * (window.devicePixelRatio || 1)))) buildPlot();
      pctx.setTransform(1, 0, 0, 1, 0, 0);
      pctx.drawImage(plotBase, 0, 0);
      const { X, Y, top, bottom, H, dpr } = plotFrame;
      pctx.scale(dpr, dpr);
      const x = X(S.time);
      pctx.strokeStyle = "#c0392b"; pctx.lineWidth = 1.5;
      pctx.beginPath(); pctx.moveTo(x, top); pctx.lineTo(x, H - bottom); pctx.stroke();
      const f = S.frame;
      for (const [name, color] of SERIES) {
        const v = values[name][f];
        if (!Number.isFinite(v)) continue;
        pctx.fillStyle = color; pctx.beginPath(); pctx.arc(X(time[f]), Y(v), 3, 0, 2 * Math.PI); pctx.fill();
      }
    }

    function seekFromPlot(event) {
      if (!plotFrame) return;
      const rect = plot.getBoundingClientRect();
      const { left, right, W } = plotFrame;
      const u = (event.clientX - rect.left - left) / (W - left - right);
      setTime(t0 + Math.min(1, Math.max(0, u)) * duration);
    }
    plot.addEventListener("pointerdown", (e) => { plot.setPointerCapture(e.pointerId); seekFromPlot(e); });
    plot.addEventListener("pointermove", (e) => { if (e.buttons & 1) seekFromPlot(e); });

    // --- playback
    function setTime(t) {
      S.time = Math.min(t1, Math.max(t0, Number(t)));
      S.dirty = true;
    }
    function play() {
      if (S.time >= t1 && duration > 0) S.time = t0;
      S.playing = duration > 0;
      S.dirty = true;
    }
    function pause() { S.playing = false; S.dirty = true; }

    slider.addEventListener("input", () => setTime(parseFloat(slider.value)));
    playButton.addEventListener("click", () => (S.playing ? pause() : play()));
    $("speed").addEventListener("change", (e) => { S.speed = parseFloat(e.target.value); });
    $("loop").addEventListener("change", (e) => { S.loop = e.target.checked; });
    document.addEventListener("keydown", (e) => {
      const tag = (e.target && e.target.tagName) || "";
      if (tag === "SELECT" || tag === "BUTTON" || (tag === "INPUT" && e.target.type !== "range")) return;
      if (e.key === " ") { e.preventDefault(); S.playing ? pause() : play(); }
      else if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
        e.preventDefault();
        pause();
        const f = Math.min(T - 1, Math.max(0, S.frame + (e.key === "ArrowRight" ? 1 : -1)));
        setTime(time[f]);
      } else if (e.key === "Home") { setTime(t0); }
      else if (e.key === "r") { Object.assign(camera, home, { target: home.target.slice() }); S.dirty = true; }
    });

    // --- orbit camera: drag rotates, wheel zooms, right- / shift- / middle-drag pans, a click picks
    let drag = null;
    canvas.addEventListener("contextmenu", (e) => e.preventDefault());
    canvas.addEventListener("pointerdown", (e) => {
      canvas.setPointerCapture(e.pointerId);
      canvas.focus();
      drag = { x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY, pan: e.button !== 0 || e.shiftKey, button: e.button };
      canvas.classList.add("dragging");
    });
    canvas.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const e0 = eye(), f = normalize(sub(camera.target, e0)), r = normalize(cross(f, [0, 0, 1])), u = cross(r, f);
        const perPixel = 2 * camera.distance * Math.tan(camera.fovy / 2) / Math.max(1, canvas.clientHeight);
        for (let k = 0; k < 3; k++) camera.target[k] += (-dx * r[k] + dy * u[k]) * perPixel;
      } else {
        camera.yaw -= dx * 0.008;
        camera.pitch = Math.min(1.55, Math.max(-1.55, camera.pitch + dy * 0.008));
      }
      S.dirty = true;
    });
    canvas.addEventListener("pointerup", (e) => {
      if (drag && drag.button === 0 && Math.hypot(e.clientX - drag.x0, e.clientY - drag.y0) < 4) {
        select(pickAt(e.clientX, e.clientY));
      }
      drag = null;
      canvas.classList.remove("dragging");
    });
    canvas.addEventListener("dblclick", (e) => {
      const body = pickAt(e.clientX, e.clientY);
      if (body < 0) return;
      updatePoses();
      const o = body * 7, q = [poses[o + 3], poses[o + 4], poses[o + 5], poses[o + 6]];
      const c = quatRotate(q, bodyCentre[body]);
      camera.target = [poses[o] + c[0], poses[o + 1] + c[1], poses[o + 2] + c[2]];
      S.dirty = true;
    });
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      camera.distance = Math.min(diagonal * 100, Math.max(diagonal * 1e-3, camera.distance * Math.exp(e.deltaY * 0.001)));
      S.dirty = true;
    }, { passive: false });
    if (window.ResizeObserver) new ResizeObserver(() => { S.dirty = true; plotBase = null; }).observe($("app"));
    window.addEventListener("resize", () => { S.dirty = true; plotBase = null; });

    // --- the loop: redraw when something changed; while playing, time advances with the wall clock
    let last = null, fpsFrames = 0, fpsSince = null;
    function tick(now) {
      requestAnimationFrame(tick);
      const dt = last === null ? 0 : Math.min(0.25, (now - last) / 1000);
      last = now;
      if (S.playing) {
        let t = S.time + dt * S.speed;
        if (t >= t1) {
          if (S.loop && duration > 0) t = t0 + ((t - t0) % duration);
          else { t = t1; S.playing = false; }
        }
        S.time = t;
        S.dirty = true;
        fpsFrames++;
        if (fpsSince === null) fpsSince = now;
        if (now - fpsSince >= 500) { fps = 1000 * fpsFrames / (now - fpsSince); fpsFrames = 0; fpsSince = now; }
      } else {
        fpsSince = null; fpsFrames = 0;
      }
      if (S.dirty) { S.dirty = false; draw(); }
    }

    $("summary").textContent = `${N} bodies · ${T} frames · ${fmt(duration, 4)} s`;

    // --- the hooks tests and scripts use
    Object.assign(api, {
      bodyCount: N,
      frameCount: T,
      timeRange: [t0, t1],
      names: data.names,
      mass: data.mass,
      time: () => S.time,
      frame: () => S.frame,
      setTime: (t) => { setTime(t); draw(); return S.time; },
      play,
      pause,
      playing: () => S.playing,
      setSpeed: (x) => { S.speed = Number(x); },
      project,
      pick: pickAt,
      select: (b) => { select(b); draw(); },
      selected: () => S.selected,
      render: () => draw(),
      fps: () => fps,
    });
    draw();
    requestAnimationFrame(tick);
    api.ready = true;
  }

  main().catch((error) => { console.error(error); fail(error && error.message ? error.message : error); });
})();
