// The replay page: the match in 3D with play/pause, speed, seeking, the scoreboard and the
// referee's events on a clickable timeline.
import { ReplayData, type RefereeEvent } from "../replay";
import { SceneView } from "../scene";
import { PageError, Scoreboard, clock, describeEvent, el, setText } from "../ui";
import { drawStats } from "./plots";

const SPEEDS = [0.25, 0.5, 1, 2, 4, 8, 16];
const EVENT_LEAD_MS = 2000; // clicking an event shows the 2 s before it
const TIMELINE_TYPES = new Set(["goal", "penalty", "card", "ball_out", "kickoff", "dropped_ball", "state"]);

/** Why a replay cannot be shown, as a sentence and a way on (never the API's raw answer). */
function unavailable(root: HTMLElement, replayId: string, error: unknown, back: string): void {
  const status = error instanceof PageError ? error.status : 0;
  const text = status === 404
    ? `There is no replay "${replayId}" that you may watch. The match may not have ended yet (its replay is written when it ends), it may be another team's, or the link may be mistyped.`
    : status === 422
      ? `The replay of "${replayId}" cannot be read: its file is damaged or of an unknown format.`
      : error instanceof Error ? error.message : String(error);
  root.replaceChildren(
    el("h1", {}, "Replay not available"),
    el("p", { class: "error", "data-testid": "error" }, text),
    el("p", {}, el("a", { href: back, "data-testid": "back-link" }, "the matches you may watch")),
  );
}

export async function replayPage(root: HTMLElement, api: string, replayId: string, back = "/watch/"): Promise<void> {
  let data: ReplayData;
  try {
    data = await ReplayData.open(`${api}/replays/${encodeURIComponent(replayId)}`);
  } catch (error) {
    unavailable(root, replayId, error, back);
    return;
  }
  const meta = data.meta;
  const board = new Scoreboard(meta.match_id, meta.teams ?? null);
  const canvas = el("canvas", { class: "view", "data-testid": "scene" });
  const play = el("button", { "data-testid": "play" }, "Play");
  const speed = el("select", { "data-testid": "speed" });
  for (const s of SPEEDS) speed.append(el("option", { value: String(s), ...(s === 1 ? { selected: "" } : {}) }, `${s}x`));
  const seek = el("input", {
    type: "range", class: "seek", min: "0", max: String(meta.duration_ms), step: "40", value: "0", "data-testid": "seek",
  });
  const now = el("span", { class: "time", "data-testid": "time" }, "00:00");
  // The marks sit on a track as wide as the slider's thumb travels (both in one column), so a
  // mark is where the thumb is at its time.
  const track = el("div", { class: "track" });
  const timeline = el("div", { class: "timeline", "data-testid": "timeline" }, track);
  const list = el("ol", { class: "events", "data-testid": "events" });
  const shown = meta.events.filter((e) => TIMELINE_TYPES.has(e.type) && !(e.type === "state" && e.reason === ""));
  // goals last: drawn above a state change at the same moment
  const marked = [...shown.filter((e) => e.type !== "goal"), ...shown.filter((e) => e.type === "goal")];
  for (const event of marked) {
    const left = meta.duration_ms > 0 ? (100 * event.frame_ms) / meta.duration_ms : 0;
    const mark = el("button", {
      class: `mark ${event.type} ${event.team ?? ""}`, style: `left:${left}%`, title: `${clock(event.frame_ms)} ${describeEvent(event)}`,
      "data-testid": `mark-${event.type}`, "data-ms": String(event.frame_ms),
    }, event.type === "goal" ? "G" : "");
    mark.addEventListener("click", () => jumpTo(event));
    track.append(mark);
  }
  shown.forEach((event, index) => {
    // the number is a cell of its own: it stays beside the first line when the text wraps
    const item = el("li", { "data-type": event.type },
      el("span", { class: "n", "data-testid": "event-number" }, `${index + 1}.`),
      el("button", { class: "link" }, `${clock(event.frame_ms)} ${describeEvent(event)}`));
    item.addEventListener("click", () => jumpTo(event));
    list.append(item);
  });
  const plots = el("div", { class: "plots" });
  root.append(
    board.root,
    el("div", { class: "stage" }, canvas, el("aside", {}, el("h3", {}, "Referee events"), list)),
    el("div", { class: "controls" }, play, speed, el("div", { class: "scrub" }, seek, timeline), now),
    plots,
  );
  const view = new SceneView(canvas, meta.scene);
  const poses = new Float32Array(data.stride);
  let timeMs = 0;
  let playing = false;
  let last = performance.now();
  let shownMs = -1; // the time whose poses are on screen

  function jumpTo(event: RefereeEvent): void {
    setTime(Math.max(0, event.frame_ms - EVENT_LEAD_MS));
  }
  function setTime(t: number): void {
    timeMs = Math.min(meta.duration_ms, Math.max(0, t));
    seek.value = String(timeMs);
  }
  play.addEventListener("click", () => {
    playing = !playing;
    if (playing && timeMs >= meta.duration_ms) setTime(0);
    play.textContent = playing ? "Pause" : "Play";
  });
  seek.addEventListener("input", () => setTime(Number(seek.value)));
  document.addEventListener("keydown", (e) => {
    if (e.key === " ") { play.click(); e.preventDefault(); }
  });

  await data.load(0);
  // Dynamic resolution: while playing, frames slower than 30 per second halve the rendered
  // resolution (software WebGL is bound by pixels); paused, the view is drawn in full.
  let frameMs = 16;
  function frame(at: number): void {
    const dt = at - last;
    last = at;
    frameMs = 0.9 * frameMs + 0.1 * Math.min(dt, 1000);
    view.setScale(playing && frameMs > 36 ? 0.5 : playing ? view.scale : 1);
    if (playing) {
      setTime(timeMs + dt * Number(speed.value));
      if (timeMs >= meta.duration_ms) { playing = false; play.textContent = "Play"; }
    }
    if (shownMs !== timeMs) { // paused and shown: nothing to pose, nothing to draw
      const game = data.sample(timeMs, poses);
      if (game !== null) {
        view.setPoses(poses);
        board.update(game);
        shownMs = timeMs;
      }
    }
    setText(now, `${clock(timeMs)} / ${clock(meta.duration_ms)}`);
    playhead(timeMs);
    view.render();
    requestAnimationFrame(frame);
  }
  let playhead: (ms: number) => void = () => undefined;
  requestAnimationFrame(frame);
  if (meta.has_stats) {
    void drawStats(plots, `${api}/replays/${encodeURIComponent(replayId)}/stats`).then((move) => { playhead = move; });
  }

  // A small handle for tests and benchmarks (read-only views of the player's state).
  (window as unknown as Record<string, unknown>).hlvsViewer = {
    meta,
    get time() { return timeMs; },
    get ready() { return shownMs === timeMs; },
    get frames() { return view.frames; },
    get scale() { return view.scale; },
    get playing() { return playing; },
    seek: (t: number) => setTime(t),
    project: (p: number[]) => view.project(p),
    pixel: (p: number[]) => { view.draw(); return view.pixel(p); },
    view,
    poses: () => Array.from(poses),
  };
}
