// Replay data from the viewer API: the meta (scene, chunk index, events) once, then chunks of
// frames on demand, so that opening and seeking never read the whole replay.

import type { SceneSpec } from "./scene";
import { PageError, type TeamNames, authFetch, sentence } from "./ui";

export interface RefereeEvent {
  type: string;
  team?: string | null;
  player?: number | null;
  reason?: string;
  sim_time_ms: number;
  frame_ms: number;
  [key: string]: unknown;
}

export interface GameState {
  state?: string;
  secondary_state?: string;
  half?: number;
  secs_remaining?: number;
  score?: { red: number; blue: number };
  [key: string]: unknown;
}

export interface ReplayMeta {
  id: string;
  match_id: string;
  version: number;
  rate_hz: number;
  duration_ms: number;
  body_count: number;
  chunks: [number, number, number][]; // first_ms, last_ms, frames
  events: RefereeEvent[];
  scene: SceneSpec;
  has_stats: boolean;
  teams?: TeamNames | null;
}

interface Chunk {
  times: number[];
  games: GameState[];
  poses: Float32Array; // frames x bodies x 7
}

export class ReplayData {
  private readonly chunks = new Map<number, Chunk>();
  private readonly pending = new Map<number, Promise<Chunk>>();
  readonly stride: number;

  private constructor(readonly base: string, readonly meta: ReplayMeta) {
    this.stride = meta.body_count * 7;
  }

  static async open(base: string): Promise<ReplayData> {
    const response = await authFetch(`${base}/meta`);
    if (!response.ok) throw new PageError(await sentence(response, `${base}/meta`), response.status);
    return new ReplayData(base, (await response.json()) as ReplayMeta);
  }

  chunkAt(timeMs: number): number {
    const chunks = this.meta.chunks;
    let lo = 0;
    let hi = chunks.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (chunks[mid][0] <= timeMs) lo = mid;
      else hi = mid - 1;
    }
    return lo;
  }

  loaded(index: number): boolean {
    return this.chunks.has(index);
  }

  load(index: number): Promise<Chunk> {
    const have = this.chunks.get(index);
    if (have) return Promise.resolve(have);
    let waiting = this.pending.get(index);
    if (!waiting) {
      waiting = authFetch(`${this.base}/chunks/${index}`)
        .then(async (response) => {
          if (!response.ok) throw new Error(`chunk ${index}: ${response.status}`);
          const buffer = await response.arrayBuffer();
          const jsonLength = new DataView(buffer).getUint32(0, true);
          const head = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, jsonLength)));
          const start = 4 + jsonLength + ((4 - (jsonLength % 4)) % 4);
          const chunk = { times: head.times, games: head.games, poses: new Float32Array(buffer, start) };
          this.chunks.set(index, chunk);
          this.pending.delete(index);
          if (this.chunks.size > 120) this.evict(index);
          return chunk;
        });
      this.pending.set(index, waiting);
    }
    return waiting;
  }

  private evict(keep: number): void {
    for (const index of this.chunks.keys()) {
      if (Math.abs(index - keep) > 30) this.chunks.delete(index);
    }
  }

  /** Fill `out` with the poses at `timeMs` (interpolated between frames); the game state of the
   * frame at or before it. Null while the chunk is not loaded yet (it is then requested). */
  sample(timeMs: number, out: Float32Array): GameState | null {
    const k = this.chunkAt(timeMs);
    const chunk = this.chunks.get(k);
    if (!chunk) {
      void this.load(k);
      return null;
    }
    if (k + 1 < this.meta.chunks.length && !this.loaded(k + 1)) void this.load(k + 1);
    const times = chunk.times;
    let i = 0;
    while (i + 1 < times.length && times[i + 1] <= timeMs) i++;
    const stride = this.stride;
    const a = chunk.poses.subarray(i * stride, (i + 1) * stride);
    let b: Float32Array | null = null;
    let tb = 0;
    if (i + 1 < times.length) {
      b = chunk.poses.subarray((i + 1) * stride, (i + 2) * stride);
      tb = times[i + 1];
    } else {
      const next = this.chunks.get(k + 1);
      if (next) {
        b = next.poses.subarray(0, stride);
        tb = next.times[0];
      }
    }
    const ta = times[i];
    const w = b && tb > ta ? Math.min(1, Math.max(0, (timeMs - ta) / (tb - ta))) : 0;
    if (!b || w === 0) out.set(a);
    else interpolate(a, b, w, out);
    return chunk.games[i];
  }
}

/** Positions linearly, orientations by normalised linear blend (frames are 40 ms apart). */
export function interpolate(a: Float32Array, b: Float32Array, w: number, out: Float32Array): void {
  for (let o = 0; o < a.length; o += 7) {
    out[o] = a[o] + (b[o] - a[o]) * w;
    out[o + 1] = a[o + 1] + (b[o + 1] - a[o + 1]) * w;
    out[o + 2] = a[o + 2] + (b[o + 2] - a[o + 2]) * w;
    const dot = a[o + 3] * b[o + 3] + a[o + 4] * b[o + 4] + a[o + 5] * b[o + 5] + a[o + 6] * b[o + 6];
    const s = dot < 0 ? -1 : 1;
    let norm = 0;
    for (let j = 3; j < 7; j++) {
      const q = a[o + j] + (s * b[o + j] - a[o + j]) * w;
      out[o + j] = q;
      norm += q * q;
    }
    norm = Math.sqrt(norm) || 1;
    for (let j = 3; j < 7; j++) out[o + j] /= norm;
  }
}
