// The 3D scene: field, goals, ball and robots built from a replay's scene description, posed
// body by body from frames (x y z qw qx qy qz per body, MuJoCo's world frame, z up).
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { mergeGeometries } from "three/examples/jsm/utils/BufferGeometryUtils.js";

export interface GeomSpec {
  name: string;
  body: number;
  type: string;
  size: number[];
  pos: number[];
  quat: number[];
  rgba: number[];
  group: number;
  pattern?: { colors: number[][]; repeat: number[]; cube: boolean };
  texture?: string; // one of the look's materials: "look:turf", "look:ball", "look:net"
}

/** The match's look (simulator/world/look.py `Look.summary`): what the viewer draws of it. */
export interface LookSpec {
  texture_seed: number;
  turf_colors: number[][]; // light and dark mowing stripe, mean colours
  stripe_m: number;
  ball_colors: number[][]; // panels, patches
  sky_colors: number[][]; // sky top, sky at the horizon, stands
}

export interface RobotSpec {
  team: string;
  number: number;
  model: string;
  root_body: number;
}

export interface SceneSpec {
  bodies: string[];
  geoms: GeomSpec[];
  cameras: { name: string; pos: number[]; quat: number[]; fovy_deg: number }[];
  robots: RobotSpec[];
  field: Record<string, number | string>;
  look?: LookSpec;
}

export const TEAM_CSS: Record<string, string> = { red: "#d91f1a", blue: "#1a40e6" };

function colour(rgb: number[]): THREE.Color {
  return new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace);
}

function numberSprite(robot: RobotSpec): THREE.Sprite {
  const canvas = document.createElement("canvas");
  canvas.width = canvas.height = 64;
  const ctx = canvas.getContext("2d")!;
  ctx.fillStyle = TEAM_CSS[robot.team] ?? "#444";
  ctx.beginPath();
  ctx.arc(32, 32, 30, 0, 2 * Math.PI);
  ctx.fill();
  ctx.fillStyle = "#fff";
  ctx.font = "bold 40px sans-serif";
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  ctx.fillText(String(robot.number), 32, 34);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false }));
  sprite.scale.set(0.3, 0.3, 1);
  sprite.renderOrder = 10;
  return sprite;
}

/** A unit primitive that geoms are drawn as (scaled by their sizes): boxes, spheres (also
 * ellipsoids and unknown shapes), cylinders; a capsule is an open tube with a low-poly half
 * sphere at each end, facing outwards. Few triangles: software WebGL pays for each one,
 * however small on screen. */
type Primitive = "box" | "sphere" | "cylinder" | "tube" | "cap";

function unitGeometry(kind: Primitive): THREE.BufferGeometry {
  const shape =
    kind === "box" ? new THREE.BoxGeometry(2, 2, 2)
    : kind === "sphere" ? new THREE.SphereGeometry(1, 10, 6)
    : kind === "cap" ? new THREE.SphereGeometry(1, 8, 2, 0, 2 * Math.PI, 0, Math.PI / 2).rotateX(Math.PI / 2) // +z half, rim on the tube's
    : kind === "tube" ? new THREE.CylinderGeometry(1, 1, 2, 8, 1, true).rotateX(Math.PI / 2)
    : new THREE.CylinderGeometry(1, 1, 2, 12).rotateX(Math.PI / 2); // along z like MuJoCo's
  shape.deleteAttribute("uv");
  return shape;
}

/** Static boxes this thin (half size, both short sides) and four times as long are a net's
 * cords (1 cm thick): drawn as lines, about a pixel wide at the viewer's distances, where a
 * box cost twelve triangles (a goal's net has over a hundred cords). */
const CORD_HALF_M = 0.006;

/** The two ends of a cord-like box, in the world (static geoms: their frame is the world's);
 * null for any other box. */
function cordEnds(g: GeomSpec): number[] | null {
  const half = g.size.slice(0, 3);
  const long = half.indexOf(Math.max(...half));
  const short = half.filter((_, i) => i !== long);
  if (short.some((h) => h > CORD_HALF_M) || half[long] < 4 * Math.max(...short)) return null;
  const axis = new THREE.Vector3(long === 0 ? 1 : 0, long === 1 ? 1 : 0, long === 2 ? 1 : 0)
    .applyQuaternion(new THREE.Quaternion(g.quat[1], g.quat[2], g.quat[3], g.quat[0]))
    .multiplyScalar(half[long]);
  const centre = new THREE.Vector3(g.pos[0], g.pos[1], g.pos[2]);
  return [...centre.clone().sub(axis).toArray(), ...centre.clone().add(axis).toArray()];
}

/** One piece of a geom: a unit primitive placed in its body's frame. */
interface Piece {
  kind: Primitive;
  local: THREE.Matrix4;
}

/** A geom as unit primitives in its body's frame (a capsule is a cylinder and two spheres). */
function pieces(g: GeomSpec): Piece[] {
  const [a, b, c] = g.size;
  const frame = new THREE.Matrix4().compose(
    new THREE.Vector3(g.pos[0], g.pos[1], g.pos[2]),
    new THREE.Quaternion(g.quat[1], g.quat[2], g.quat[3], g.quat[0]),
    new THREE.Vector3(1, 1, 1),
  );
  const scaled = (x: number, y: number, z: number, dz = 0, flip = false): THREE.Matrix4 =>
    frame.clone().multiply(new THREE.Matrix4().makeTranslation(0, 0, dz))
      .multiply(new THREE.Matrix4().makeRotationX(flip ? Math.PI : 0)).scale(new THREE.Vector3(x, y, z));
  switch (g.type) {
    case "box":
      return [{ kind: "box", local: scaled(a, b, c) }];
    case "cylinder":
      return [{ kind: "cylinder", local: scaled(a, a, b) }];
    case "capsule":
      return [
        { kind: "tube", local: scaled(a, a, b) },
        { kind: "cap", local: scaled(a, a, a, b) },
        { kind: "cap", local: scaled(a, a, a, -b, true) },
      ];
    case "ellipsoid":
      return [{ kind: "sphere", local: scaled(a, b, c) }];
    default:
      return [{ kind: "sphere", local: scaled(a, a, a) }];
  }
}

/** A sphere whose triangles alternate the pattern's two colours (a football on a low-poly
 * sphere), in its geom's frame. */
function patternedSphere(g: GeomSpec, colours: THREE.Color[]): THREE.BufferGeometry {
  const shape = new THREE.SphereGeometry(g.size[0], 16, 10).toNonIndexed();
  shape.deleteAttribute("uv");
  const count = shape.getAttribute("position").count;
  const rgb = new Float32Array(count * 3);
  for (let v = 0; v < count; v++) {
    const c = colours[Math.floor(v / 3) % 2];
    rgb.set([c.r, c.g, c.b], v * 3);
  }
  shape.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
  return shape;
}

/** The classic football on a sphere: a triangle takes the patch colour when its centre is
 * nearer one of the 12 icosahedron vertices (the pentagons) than one of the 20 face centres
 * (the hexagons), as the simulator's ball texture is drawn. */
function footballSphere(g: GeomSpec, panel: THREE.Color, patch: THREE.Color): THREE.BufferGeometry {
  const shape = new THREE.SphereGeometry(g.size[0], 32, 20).toNonIndexed();
  shape.deleteAttribute("uv");
  const ico = new THREE.IcosahedronGeometry(1, 0).toNonIndexed().getAttribute("position");
  const vertices: THREE.Vector3[] = [];
  const centres: THREE.Vector3[] = [];
  for (let f = 0; f < ico.count; f += 3) {
    const corners = [0, 1, 2].map((k) => new THREE.Vector3().fromBufferAttribute(ico, f + k).normalize());
    centres.push(corners[0].clone().add(corners[1]).add(corners[2]).normalize());
    for (const c of corners) if (!vertices.some((v) => v.distanceTo(c) < 1e-3)) vertices.push(c);
  }
  const position = shape.getAttribute("position");
  const rgb = new Float32Array(position.count * 3);
  const centre = new THREE.Vector3();
  const p = new THREE.Vector3();
  for (let v = 0; v < position.count; v += 3) {
    centre.set(0, 0, 0);
    for (let k = 0; k < 3; k++) centre.add(p.fromBufferAttribute(position, v + k));
    centre.normalize();
    const pent = Math.max(...vertices.map((d) => d.dot(centre))) + 0.02;
    const hex = Math.max(...centres.map((d) => d.dot(centre)));
    const c = pent > hex ? patch : panel;
    for (let k = 0; k < 3; k++) rgb.set([c.r, c.g, c.b], (v + k) * 3);
  }
  shape.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
  return shape;
}

/** The look's turf: mowing stripes across the pitch (`stripe_m` wide along x, light first from
 * x = 0, as MuJoCo lays the texture), as coloured quads. */
function stripedTurf(g: GeomSpec, look: LookSpec): THREE.BufferGeometry {
  const [halfX, halfY] = g.size;
  const colours = look.turf_colors.map(colour);
  const first = Math.floor(-halfX / look.stripe_m);
  const last = Math.ceil(halfX / look.stripe_m);
  const position: number[] = [];
  const rgb: number[] = [];
  for (let i = first; i < last; i++) {
    const x0 = Math.max(-halfX, i * look.stripe_m);
    const x1 = Math.min(halfX, (i + 1) * look.stripe_m);
    const c = colours[((i % 2) + 2) % 2];
    for (const [x, y] of [[x0, -halfY], [x1, -halfY], [x1, halfY], [x0, -halfY], [x1, halfY], [x0, halfY]]) {
      position.push(x, y, 0);
      rgb.push(c.r, c.g, c.b);
    }
  }
  const shape = new THREE.BufferGeometry();
  shape.setAttribute("position", new THREE.BufferAttribute(new Float32Array(position), 3));
  shape.setAttribute("color", new THREE.BufferAttribute(new Float32Array(rgb), 3));
  return shape;
}

/** The turf's checker pattern as coloured quads (no texture to sample: the turf covers most
 * pixels, and software WebGL pays for every texture read). Same cells as the texture MuJoCo
 * describes: two colours, 2 x repeat cells across the plane, multiplied by `tint`. */
function turfGeometry(g: GeomSpec, tint: THREE.Color): THREE.BufferGeometry {
  const pattern = g.pattern!;
  const [halfX, halfY] = g.size;
  const colours = pattern.colors.map((c) => colour(c).multiply(tint));
  const nx = Math.ceil(2 * pattern.repeat[0] - 1e-6);
  const ny = Math.ceil(2 * pattern.repeat[1] - 1e-6);
  const cellX = (2 * halfX) / (2 * pattern.repeat[0]);
  const cellY = (2 * halfY) / (2 * pattern.repeat[1]);
  const position = new Float32Array(nx * ny * 18);
  const rgb = new Float32Array(nx * ny * 18);
  let o = 0;
  for (let j = 0; j < ny; j++) {
    for (let i = 0; i < nx; i++) {
      const x0 = -halfX + i * cellX;
      const x1 = Math.min(halfX, x0 + cellX);
      const y0 = -halfY + j * cellY;
      const y1 = Math.min(halfY, y0 + cellY);
      const c = colours[(i + j + 1) % 2]; // the texture's first row is its top (flipY)
      for (const [x, y] of [[x0, y0], [x1, y0], [x1, y1], [x0, y0], [x1, y1], [x0, y1]]) {
        position.set([x, y, 0], o);
        rgb.set([c.r, c.g, c.b], o);
        o += 3;
      }
    }
  }
  const shape = new THREE.BufferGeometry();
  shape.setAttribute("position", new THREE.BufferAttribute(position, 3));
  shape.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
  return shape;
}

interface Instanced {
  mesh: THREE.InstancedMesh;
  bodies: number[]; // per instance
  locals: THREE.Matrix4[]; // per instance, in its body's frame
}

/**
 * The scene in few draw calls and little work per frame (software WebGL pays per call, per
 * vertex and per pixel): the static world (lines, goals) merged into one mesh; every moving
 * geom an instance of a few unit primitives (boxes, spheres, cylinders, capsule tubes and ends),
 * one instanced mesh each, whose instance matrices are the only thing that changes per frame;
 * the turf as flat-coloured quads.
 */
export class SceneView {
  readonly renderer: THREE.WebGLRenderer;
  readonly camera: THREE.PerspectiveCamera;
  readonly scene = new THREE.Scene();
  private readonly instanced: Instanced[] = [];
  private readonly posed: { object: THREE.Object3D; body: number; local: THREE.Matrix4 }[] = [];
  private readonly bodies: THREE.Matrix4[];
  private readonly labels: { sprite: THREE.Sprite; body: number }[] = [];
  private readonly controls: OrbitControls;
  private readonly position = new THREE.Vector3();
  private readonly rotation = new THREE.Quaternion();
  private readonly unit = new THREE.Vector3(1, 1, 1);
  private readonly product = new THREE.Matrix4();
  private dirty = true; // something changed since the last drawing
  frames = 0; // drawings

  constructor(readonly canvas: HTMLCanvasElement, readonly spec: SceneSpec) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    this.renderer.setPixelRatio(1);
    this.scene.background = spec.look ? colour(spec.look.sky_colors[1]) : new THREE.Color(0x9ab8d8);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445544, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(2, 3, 10);
    this.scene.add(sun);
    this.bodies = spec.bodies.map(() => new THREE.Matrix4());
    const staticParts: [THREE.BufferGeometry[], THREE.BufferGeometry[]] = [[], []];
    const cords: number[] = []; // line ends, x y z
    const cordColours: number[] = [];
    const moving = new Map<string, { kind: Primitive; transparent: boolean; bodies: number[]; locals: THREE.Matrix4[]; colours: THREE.Color[] }>();
    for (const g of spec.geoms) {
      if (g.group >= 3) continue; // MuJoCo's hidden groups (collision-only helpers)
      const transparent = g.rgba[3] < 1;
      const look = spec.look;
      if (g.type === "plane" && g.texture === "look:turf" && look) {
        const turf = new THREE.Mesh(stripedTurf(g, look), new THREE.MeshBasicMaterial({ vertexColors: true }));
        turf.position.set(g.pos[0], g.pos[1], g.pos[2] - 0.0005);
        turf.name = g.name;
        this.scene.add(turf);
        continue;
      }
      if (g.type === "sphere" && g.texture === "look:ball" && look) {
        const [panel, patch] = look.ball_colors.map(colour);
        const mesh = new THREE.Mesh(footballSphere(g, panel, patch), new THREE.MeshLambertMaterial({ vertexColors: true }));
        mesh.name = g.name;
        mesh.matrixAutoUpdate = false;
        const local = new THREE.Matrix4().compose(
          new THREE.Vector3(g.pos[0], g.pos[1], g.pos[2]),
          new THREE.Quaternion(g.quat[1], g.quat[2], g.quat[3], g.quat[0]), this.unit);
        this.posed.push({ object: mesh, body: g.body, local });
        this.scene.add(mesh);
        continue;
      }
      if (g.type === "plane" && g.pattern) {
        // unlit: a flat plane is evenly lit anyway, and the cheapest shader covers most pixels
        const turf = new THREE.Mesh(turfGeometry(g, new THREE.Color(0xbbbbbb)), new THREE.MeshBasicMaterial({ vertexColors: true }));
        turf.position.set(g.pos[0], g.pos[1], g.pos[2] - 0.0005);
        turf.name = g.name;
        this.scene.add(turf);
        continue;
      }
      if (g.pattern && g.type === "sphere") {
        const mesh = new THREE.Mesh(patternedSphere(g, g.pattern.colors.map(colour)), new THREE.MeshLambertMaterial({ vertexColors: true }));
        mesh.name = g.name;
        mesh.matrixAutoUpdate = false;
        const local = new THREE.Matrix4().compose(
          new THREE.Vector3(g.pos[0], g.pos[1], g.pos[2]),
          new THREE.Quaternion(g.quat[1], g.quat[2], g.quat[3], g.quat[0]), this.unit);
        this.posed.push({ object: mesh, body: g.body, local });
        this.scene.add(mesh);
        continue;
      }
      const cord = g.body === 0 && g.type === "box" ? cordEnds(g) : null;
      if (cord) { // a net's cord: one line, not a box's twelve triangles
        const c = colour(g.rgba);
        cords.push(...cord);
        cordColours.push(c.r, c.g, c.b, c.r, c.g, c.b);
        continue;
      }
      for (const piece of pieces(g)) { // other patterned shapes: in their mean colour (rgba)
        if (g.body === 0) {
          const part = unitGeometry(piece.kind).applyMatrix4(piece.local);
          const count = part.getAttribute("position").count;
          const c = colour(g.rgba);
          const rgb = new Float32Array(count * 3);
          for (let v = 0; v < count; v++) rgb.set([c.r, c.g, c.b], v * 3);
          part.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
          staticParts[transparent ? 1 : 0].push(part);
          continue;
        }
        const key = `${piece.kind}:${transparent}`;
        let group = moving.get(key);
        if (!group) moving.set(key, (group = { kind: piece.kind, transparent, bodies: [], locals: [], colours: [] }));
        group.bodies.push(g.body);
        group.locals.push(piece.local);
        group.colours.push(colour(g.rgba));
      }
    }
    const material = (transparent: boolean, vertexColors: boolean): THREE.Material =>
      new THREE.MeshLambertMaterial({ vertexColors, transparent, opacity: transparent ? 0.35 : 1, depthWrite: !transparent });
    if (cords.length > 0) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.Float32BufferAttribute(cords, 3));
      geometry.setAttribute("color", new THREE.Float32BufferAttribute(cordColours, 3));
      const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
      lines.name = "cords";
      lines.matrixAutoUpdate = false;
      this.scene.add(lines);
    }
    staticParts.forEach((parts, transparent) => {
      if (parts.length === 0) return;
      const mesh = new THREE.Mesh(mergeGeometries(parts), material(transparent === 1, true));
      mesh.matrixAutoUpdate = false;
      if (transparent) mesh.renderOrder = 1;
      this.scene.add(mesh);
    });
    for (const group of moving.values()) {
      const mesh = new THREE.InstancedMesh(unitGeometry(group.kind), material(group.transparent, false), group.bodies.length);
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      group.colours.forEach((c, k) => mesh.setColorAt(k, c));
      mesh.frustumCulled = false;
      mesh.matrixAutoUpdate = false;
      if (group.transparent) mesh.renderOrder = 1;
      this.instanced.push({ mesh, bodies: group.bodies, locals: group.locals });
      this.scene.add(mesh);
    }
    for (const robot of spec.robots) {
      if (robot.root_body < 0) continue;
      const sprite = numberSprite(robot);
      this.labels.push({ sprite, body: robot.root_body });
      this.scene.add(sprite);
    }
    this.camera = new THREE.PerspectiveCamera(45, 16 / 9, 0.05, 200);
    this.camera.up.set(0, 0, 1);
    const halfLength = Number(spec.field.half_length_m ?? 4.5);
    this.camera.position.set(0, -halfLength * 1.55, halfLength * 1.2);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.set(0, 0, 0);
    this.controls.addEventListener("change", () => { this.dirty = true; });
    this.controls.update();
    this.resize();
    window.addEventListener("resize", () => this.resize());
  }

  /** Render at `scale` of the canvas size (lower while playing on a slow software renderer). */
  setScale(scale: number): void {
    if (this.renderer.getPixelRatio() === scale) return;
    this.renderer.setPixelRatio(scale);
    this.resize();
  }

  get scale(): number {
    return this.renderer.getPixelRatio();
  }

  resize(): void {
    const width = this.canvas.clientWidth || 960;
    const height = this.canvas.clientHeight || 540;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  /** Pose every body from `poses` (bodies x 7 floats: x y z qw qx qy qz); allocates nothing. */
  setPoses(poses: Float32Array): void {
    const n = Math.min(this.bodies.length, poses.length / 7);
    for (let i = 1; i < n; i++) {
      const o = i * 7;
      this.position.set(poses[o], poses[o + 1], poses[o + 2]);
      this.rotation.set(poses[o + 4], poses[o + 5], poses[o + 6], poses[o + 3]);
      this.bodies[i].compose(this.position, this.rotation, this.unit);
    }
    for (const { mesh, bodies, locals } of this.instanced) {
      const out = mesh.instanceMatrix.array as Float32Array;
      for (let k = 0; k < bodies.length; k++) {
        this.product.multiplyMatrices(this.bodies[bodies[k]], locals[k]).toArray(out, k * 16);
      }
      mesh.instanceMatrix.needsUpdate = true;
    }
    for (const { object, body, local } of this.posed) {
      object.matrix.multiplyMatrices(this.bodies[body], local);
      object.matrixWorldNeedsUpdate = true;
    }
    for (const label of this.labels) {
      const o = label.body * 7;
      label.sprite.position.set(poses[o], poses[o + 1], poses[o + 2] + 0.45);
    }
    this.dirty = true;
  }

  /** Draw if anything changed since the last drawing (poses, camera, size); called every
   * animation frame, it costs nothing while the view stands still. */
  render(): void {
    this.controls.update();
    if (this.dirty) this.draw();
  }

  /** Draw now. */
  draw(): void {
    this.renderer.render(this.scene, this.camera);
    this.frames += 1;
    this.dirty = false;
  }

  /** The colour drawn where a world point lands on the canvas (RGBA bytes), for tests: call
   * it right after `draw()`, in the same task (the drawing buffer is not preserved). */
  pixel(point: number[]): number[] {
    const v = new THREE.Vector3(point[0], point[1], point[2]).project(this.camera);
    const x = Math.round(((v.x + 1) / 2) * this.canvas.width);
    const y = Math.round(((1 - v.y) / 2) * this.canvas.height);
    const gl = this.renderer.getContext();
    const out = new Uint8Array(4);
    gl.readPixels(x, this.canvas.height - 1 - y, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, out);
    return Array.from(out);
  }

  /** Canvas pixel coordinates of a world point (for tests and overlays). */
  project(point: number[]): number[] {
    const v = new THREE.Vector3(point[0], point[1], point[2]).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return [rect.left + ((v.x + 1) / 2) * rect.width, rect.top + ((1 - v.y) / 2) * rect.height];
  }
}
