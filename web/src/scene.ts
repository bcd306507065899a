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
}

export const TEAM_CSS: Record<string, string> = { red: "#d91f1a", blue: "#1a40e6" };

function colour(rgb: number[]): THREE.Color {
  return new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace);
}

function checker(spec: NonNullable<GeomSpec["pattern"]>): THREE.Texture {
  const canvas = document.createElement("canvas");
  canvas.width = canvas.height = 64;
  const ctx = canvas.getContext("2d")!;
  const css = spec.colors.map((c) => `#${colour(c).getHexString(THREE.SRGBColorSpace)}`);
  for (let y = 0; y < 2; y++) {
    for (let x = 0; x < 2; x++) {
      ctx.fillStyle = css[(x + y) % 2];
      ctx.fillRect(x * 32, y * 32, 32, 32);
    }
  }
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  texture.magFilter = THREE.NearestFilter;
  const [u, v] = spec.cube ? [2, 2] : spec.repeat;
  texture.repeat.set(u, v);
  return texture;
}

function geometry(g: GeomSpec): THREE.BufferGeometry {
  const [a, b, c] = g.size;
  switch (g.type) {
    case "plane":
      return new THREE.PlaneGeometry(2 * a, 2 * b);
    case "box":
      return new THREE.BoxGeometry(2 * a, 2 * b, 2 * c);
    case "capsule":
      return new THREE.CapsuleGeometry(a, 2 * b, 2, 8).rotateX(Math.PI / 2);
    case "cylinder":
      return new THREE.CylinderGeometry(a, a, 2 * b, 12).rotateX(Math.PI / 2);
    case "ellipsoid":
      return new THREE.SphereGeometry(1, 12, 8).scale(a, b, c);
    default:
      return new THREE.SphereGeometry(a, 16, 10);
  }
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

/** One geom's triangles in its body's frame, with a colour per vertex (a checker pattern
 * alternates colours per triangle, which reads as a football on a low-poly sphere). */
function bodyGeometry(g: GeomSpec): THREE.BufferGeometry {
  const shape = geometry(g).toNonIndexed();
  shape.deleteAttribute("uv");
  shape.applyMatrix4(new THREE.Matrix4().compose(
    new THREE.Vector3(g.pos[0], g.pos[1], g.pos[2]),
    new THREE.Quaternion(g.quat[1], g.quat[2], g.quat[3], g.quat[0]),
    new THREE.Vector3(1, 1, 1),
  ));
  const count = shape.getAttribute("position").count;
  const colours = new Float32Array(count * 3);
  const pattern = g.pattern && g.type !== "plane" ? g.pattern.colors.map(colour) : null;
  const plain = colour(g.rgba);
  for (let v = 0; v < count; v++) {
    const c = pattern ? pattern[Math.floor(v / 3) % 2] : plain;
    colours.set([c.r, c.g, c.b], v * 3);
  }
  shape.setAttribute("color", new THREE.BufferAttribute(colours, 3));
  const index = new Uint16Array(count * 4);
  const weight = new Float32Array(count * 4);
  for (let v = 0; v < count; v++) {
    index[v * 4] = g.body;
    weight[v * 4] = 1;
  }
  shape.setAttribute("skinIndex", new THREE.BufferAttribute(index, 4));
  shape.setAttribute("skinWeight", new THREE.BufferAttribute(weight, 4));
  return shape;
}

/**
 * The scene in few draw calls (software WebGL pays per call): every opaque geom of every body
 * is merged into one skinned mesh with one bone per body, posed by setting the bones; the
 * turf (textured) and the see-through nets are meshes of their own.
 */
export class SceneView {
  readonly renderer: THREE.WebGLRenderer;
  readonly camera: THREE.PerspectiveCamera;
  readonly scene = new THREE.Scene();
  readonly bones: THREE.Bone[] = [];
  private readonly labels: { sprite: THREE.Sprite; body: number }[] = [];
  private readonly controls: OrbitControls;
  frames = 0;

  constructor(readonly canvas: HTMLCanvasElement, readonly spec: SceneSpec) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    this.scene.background = new THREE.Color(0x9ab8d8);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445544, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(2, 3, 10);
    this.scene.add(sun);
    for (let i = 0; i < spec.bodies.length; i++) {
      const bone = new THREE.Bone();
      bone.name = spec.bodies[i];
      this.bones.push(bone);
      this.scene.add(bone);
    }
    const opaque: THREE.BufferGeometry[] = [];
    const seeThrough: THREE.BufferGeometry[] = [];
    for (const g of spec.geoms) {
      if (g.group >= 3) continue; // MuJoCo's hidden groups (collision-only helpers)
      if (g.type === "plane" && g.pattern) {
        // unlit: a flat plane is evenly lit anyway, and the cheapest shader covers most pixels
        const turf = new THREE.Mesh(geometry(g), new THREE.MeshBasicMaterial({ map: checker(g.pattern), color: 0xbbbbbb }));
        turf.position.set(g.pos[0], g.pos[1], g.pos[2] - 0.0005);
        turf.name = g.name;
        this.scene.add(turf);
        continue;
      }
      (g.rgba[3] < 1 ? seeThrough : opaque).push(bodyGeometry(g));
    }
    const skeleton = new THREE.Skeleton(this.bones, this.bones.map(() => new THREE.Matrix4()));
    for (const [parts, transparent] of [[opaque, false], [seeThrough, true]] as const) {
      if (parts.length === 0) continue;
      const material = new THREE.MeshLambertMaterial({
        vertexColors: true, transparent, opacity: transparent ? 0.35 : 1, depthWrite: !transparent,
      });
      const mesh = new THREE.SkinnedMesh(mergeGeometries([...parts]), material);
      mesh.bind(skeleton, new THREE.Matrix4());
      mesh.frustumCulled = false;
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
  }

  /** Pose every body from `poses` (bodies x 7 floats: x y z qw qx qy qz). */
  setPoses(poses: Float32Array): void {
    const n = Math.min(this.bones.length, poses.length / 7);
    for (let i = 1; i < n; i++) {
      const o = i * 7;
      const bone = this.bones[i];
      bone.position.set(poses[o], poses[o + 1], poses[o + 2]);
      bone.quaternion.set(poses[o + 4], poses[o + 5], poses[o + 6], poses[o + 3]);
    }
    for (const label of this.labels) {
      const o = label.body * 7;
      label.sprite.position.set(poses[o], poses[o + 1], poses[o + 2] + 0.45);
    }
  }

  render(): void {
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
    this.frames += 1;
  }

  /** The colour drawn where a world point lands on the canvas (RGBA bytes), for tests. */
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
