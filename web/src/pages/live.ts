// The live page: the same scene and scoreboard fed by the match's telemetry (server-sent events
// from the viewer API), the real-time factor and each robot's connection health.
import type { GameState, RefereeEvent } from "../replay";
import { SceneView, type SceneSpec } from "../scene";
import { Scoreboard, type TeamNames, authFetch, authHeaders, clock, describeEvent, el, sentence } from "../ui";

type Handler = (data: string) => void;

/** Server-sent events read with fetch, so that the token goes in a header (EventSource
 * cannot send one). Calls `handlers[event]` with each message's data; `refused` with the
 * answer when the server has no stream to give. */
async function readEvents(url: string, handlers: Record<string, Handler>, refused: (response: Response) => Promise<void>): Promise<void> {
  const response = await fetch(url, { headers: { ...authHeaders(), Accept: "text/event-stream" } });
  if (!response.ok || !response.body) {
    await refused(response);
    return;
  }
  const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
  let buffer = "";
  for (;;) {
    const { value, done } = await reader.read();
    if (done) break;
    buffer += value;
    let cut: number;
    while ((cut = buffer.indexOf("\n\n")) >= 0) {
      const block = buffer.slice(0, cut);
      buffer = buffer.slice(cut + 2);
      let name = "message";
      const data: string[] = [];
      for (const line of block.split("\n")) {
        if (line.startsWith("event: ")) name = line.slice(7);
        else if (line.startsWith("data: ")) data.push(line.slice(6));
      }
      if (data.length) handlers[name]?.(data.join("\n"));
    }
  }
  handlers.end?.("");
}

interface LiveState extends GameState {
  sim_time_ms: number;
  real_time_factor: number;
  connected?: string[];
  robots?: Record<string, { connected: boolean; bytes_in: number; bytes_out: number; round_trip_ms: number | null }> | null;
}

function decodePoses(b64: string): { timeMs: number; poses: Float32Array } {
  const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
  const view = new DataView(bytes.buffer);
  return { timeMs: view.getUint32(0, true), poses: new Float32Array(bytes.buffer.slice(4)) };
}

/** No live view: the match has ended (a link to its replay), or is not playing now. The page
 * shows this sentence alone, not an empty scoreboard over an empty scene. */
async function notLive(root: HTMLElement, api: string, matchId: string, replayBase: string, response: Response, url: string): Promise<void> {
  const replay = await authFetch(`${api}/replays/${encodeURIComponent(matchId)}/meta`).catch(() => null);
  const title = el("h1", {}, `${matchId}`);
  if (replay?.ok) {
    const teams = ((await replay.json()) as { teams?: TeamNames | null }).teams;
    root.replaceChildren(title, el("p", { "data-testid": "live-status" },
      `This match has ended${teams?.red && teams.blue ? ` (${teams.red} v ${teams.blue})` : ""}. `,
      el("a", { href: `${replayBase}/${encodeURIComponent(matchId)}${location.search}`, "data-testid": "replay-link" }, "Watch its replay"), "."));
    return;
  }
  const text = response.status === 404
    ? "This match is not being played now, and it has no replay yet: it may not have started (reload this page when it has), it may have ended without one, or it may be another team's."
    : `Live view unavailable. ${await sentence(response, url)}`;
  root.replaceChildren(title, el("p", { class: "error", "data-testid": "live-status" }, text),
    el("p", {}, el("a", { href: "/watch/", "data-testid": "back-link" }, "the matches you may watch")));
}

export function livePage(root: HTMLElement, api: string, matchId: string, replayBase = "/watch/replay"): void {
  const board = new Scoreboard(`${matchId} (live)`);
  const status = el("div", { class: "live-status", "data-testid": "live-status" }, "waiting for telemetry...");
  const canvas = el("canvas", { class: "view", "data-testid": "scene" });
  const health = el("table", { class: "health", "data-testid": "health" });
  const list = el("ol", { class: "events", "data-testid": "events" });
  root.append(
    board.root,
    status,
    el("div", { class: "stage" }, canvas, el("aside", {}, el("h3", {}, "Robots"), health, el("h3", {}, "Referee events"), list)),
  );
  let view: SceneView | null = null;
  let latest: Float32Array | null = null;
  let updates = 0;
  let simTimeMs = 0;
  let rtf = 0;
  const handlers: Record<string, Handler> = {};
  handlers.teams = (data) => board.setNames(JSON.parse(data) as TeamNames);
  handlers.scene = (data) => {
    if (view) return;
    const header = JSON.parse(data) as { scene: SceneSpec };
    view = new SceneView(canvas, header.scene);
    if (latest) view.setPoses(latest);
  };
  handlers.poses = (data) => {
    const { timeMs, poses } = decodePoses(data);
    latest = poses;
    simTimeMs = timeMs;
    updates += 1;
    view?.setPoses(poses);
  };
  handlers.state = (data) => {
    const state = JSON.parse(data) as LiveState;
    board.update(state);
    rtf = state.real_time_factor;
    simTimeMs = Math.max(simTimeMs, state.sim_time_ms);
    status.textContent = `sim ${clock(state.sim_time_ms)}  real-time factor ${state.real_time_factor.toFixed(2)}  ${state.stepping ?? ""}`;
    const robots = state.robots ?? {};
    health.replaceChildren(
      el("tr", {}, el("th", {}, "robot"), el("th", {}, "link"), el("th", {}, "kB in/out"), el("th", {}, "RTT ms")),
      ...Object.entries(robots).map(([key, r]) =>
        el("tr", { "data-robot": key, class: r.connected ? "up" : "down" },
          el("td", {}, key), el("td", {}, r.connected ? "connected" : "down"),
          el("td", {}, `${(r.bytes_in / 1000).toFixed(0)} / ${(r.bytes_out / 1000).toFixed(0)}`),
          el("td", {}, r.round_trip_ms === null ? "-" : r.round_trip_ms.toFixed(1)))),
    );
  };
  let events = 0;
  handlers.event = (data) => {
    const event = JSON.parse(data) as RefereeEvent;
    events += 1; // the newest first, each with its number in a cell of its own
    list.prepend(el("li", { "data-type": event.type }, el("span", { class: "n" }, `${events}.`),
      el("span", {}, `${clock(event.sim_time_ms)} ${describeEvent(event)}`)));
  };
  handlers.failure = (data) => {
    // the telemetry cannot be reached: a match that is over (its replay written) says so
    status.textContent = `live view unavailable: ${JSON.parse(data)}`;
    void authFetch(`${api}/replays/${encodeURIComponent(matchId)}/meta`).then((answer) => {
      if (answer.ok) void notLive(root, api, matchId, replayBase, answer, "");
    }).catch(() => undefined);
  };
  handlers.end = () => {
    status.textContent += "  (stream closed)";
  };
  const streamUrl = `${api}/live/${encodeURIComponent(matchId)}/stream`;
  readEvents(streamUrl, handlers, (response) => notLive(root, api, matchId, replayBase, response, streamUrl)).catch((error) => {
    status.textContent += `  (stream lost: ${error})`;
  });
  // When the telemetry falls silent, the match is over (or stopped): offer its replay.
  let heardAt = performance.now();
  let offered = false;
  const heard = (handler: Handler): Handler => (data) => { heardAt = performance.now(); handler(data); };
  for (const name of ["state", "poses"]) handlers[name] = heard(handlers[name]);
  const watchdog = window.setInterval(async () => {
    if (offered || updates === 0 || performance.now() - heardAt < 6000) return;
    const replay = `${api}/replays/${encodeURIComponent(matchId)}/meta`;
    const answer = await authFetch(replay).catch(() => null); // the server may be gone too
    if (answer?.ok) {
      offered = true;
      window.clearInterval(watchdog);
      status.append("  the match is over: ", el("a", { href: `${replayBase}/${encodeURIComponent(matchId)}${location.search}`, "data-testid": "replay-link" }, "watch the replay"));
    }
  }, 2000);
  function frame(): void {
    view?.render();
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
  (window as unknown as Record<string, unknown>).hlvsLive = {
    get updates() { return updates; },
    get simTimeMs() { return simTimeMs; },
    get realTimeFactor() { return rtf; },
    get hasScene() { return view !== null; },
  };
}
