// Service pages, filled from hlvs serve's /v1 API with the session's token, each showing what
// the token's role may see: the matches (a team's own, all for an operator: queue position,
// expected start, why it waits, results, replay and live links), the queue (other teams'
// entries anonymised for a team), and for
// operators the tournament schedule and standings and the pool.
import { PageError, type Who, el, getJson, table } from "../ui";

export { table };

interface Submission {
  id: string;
  team: string;
  opponent: string;
  state: string;
  created_at: string;
  started_at: string | null;
  finished_at: string | null;
  queue_position: number | null;
  expected_start: string | null;
  waiting_reason: string | null;
  match_id: string | null;
  failure_class: string | null;
  cause: string | null;
  video: { state: string; detail: string | null } | null;
}

interface Queue {
  paused: boolean;
  slots: number;
  active: Submission[];
}

interface Schedule {
  name?: string;
  matches: Record<string, unknown>[];
  standings: Record<string, unknown>[];
}

function when(iso: string | null): string {
  return iso ? new Date(iso).toISOString().replace("T", " ").slice(0, 19) + " UTC" : "-";
}

function watchLinks(s: Submission): Node {
  const links = el("span", {});
  if (s.state === "running") links.append(el("a", { href: `/watch/live/${encodeURIComponent(s.id)}` }, "live"), " ");
  if (s.state === "done" || s.state === "failed") links.append(el("a", { href: `/watch/replay/${encodeURIComponent(s.id)}` }, "replay"));
  return links;
}

const QUEUE_COLUMNS = ["position", "submission", "team", "opponent", "state", "expected start", "reason"];

/** A finished match's result as /api/viewer/results gives it (red: the submitting team). */
export interface MatchResult {
  red: string;
  blue: string;
  score: { red: number; blue: number };
  shootout: { red: number; blue: number } | null;
  winner: "red" | "blue" | "draw" | null;
}

/** "2-1", with the shoot-out's goals apart: "0-0 (shoot-out 3-2)"; `first`: whose goals lead. */
export function scoreText(r: MatchResult, first: "red" | "blue" = "red"): string {
  const other = first === "red" ? "blue" : "red";
  const shootout = r.shootout ? ` (shoot-out ${r.shootout[first]}-${r.shootout[other]})` : "";
  return `${r.score[first]}-${r.score[other]}${shootout}`;
}

/** The result in words: for a team, its own ("won 2-1", "lost 0-1", "draw 1-1"); for an operator,
 * the winner's ("Ants won 2-1"). */
export function outcomeText(r: MatchResult, team: string | null): string {
  const own = team === r.red ? "red" : team === r.blue ? "blue" : null;
  if (r.winner === "draw" || r.winner === null) return `draw ${scoreText(r)}`;
  if (own === null) return `${r[r.winner]} won ${scoreText(r, r.winner)}`;
  return `${r.winner === own ? "won" : "lost"} ${scoreText(r, own)}`;
}

/** The video: when it is expected while pending (the service's detail), else its state. */
function videoText(s: Submission): string {
  if (!s.video) return "-";
  if (s.video.state === "pending") return s.video.detail ? `pending: ${s.video.detail}` : "pending";
  if (s.video.state === "ready") return "ready (hlvs results downloads it)";
  return s.video.state;
}

function outcome(s: Submission, result: MatchResult | undefined, team: string | null): string {
  if (result) return outcomeText(result, team);
  if (s.failure_class) return `${s.failure_class}: ${s.cause ?? ""}`;
  if (s.state === "cancelled") return s.cause ? `cancelled: ${s.cause}` : "cancelled";
  if (s.state === "done") return s.cause ?? "played (no score recorded)";
  return "-";
}

async function submissionsPage(root: HTMLElement, who: Who | null): Promise<void> {
  const [rows, results] = await Promise.all([
    getJson<Submission[]>("/v1/matches"),
    getJson<Record<string, MatchResult>>("/api/viewer/results"),
  ]);
  const operator = who?.scope === "operator";
  const team = operator ? null : (who?.team ?? null);
  root.append(el("h1", {}, operator ? "All matches" : "Your matches"), table("submissions", [
    ...(operator ? ["team"] : []), "submission", "opponent", "state", "queue position", "expected start", "reason", "finished", "result", "outcome", "video", "watch",
  ], rows.map((s) => {
    const result = results[s.id];
    return [
      ...(operator ? [s.team] : []),
      s.id, s.opponent, s.state, s.queue_position === null ? "-" : String(s.queue_position), when(s.expected_start),
      s.waiting_reason ?? "-", when(s.finished_at),
      result ? `${result.red} ${result.score.red} : ${result.score.blue} ${result.blue}${result.shootout ? ` (shoot-out ${result.shootout.red}-${result.shootout.blue})` : ""}` : "-",
      outcome(s, result, team), videoText(s), watchLinks(s),
    ];
  }), operator ? "No team has asked for a test match yet." : "No matches yet: ask for one with hlvs submit (see the README's Submission service)."));
}

interface QueueEntry {
  own: boolean;
  position: number | null;
  state: string;
  team: string;
  opponent: string;
  id: string | null;
  expected_start: string | null;
  waiting_reason: string | null;
}

async function queuePage(root: HTMLElement): Promise<void> {
  const queue = await getJson<{ paused: boolean; slots: number; active: QueueEntry[] }>("/v1/queue");
  root.append(
    el("h1", {}, "Queue"),
    el("p", { "data-testid": "queue-summary" }, `${queue.paused ? "paused" : "running"}, ${queue.slots} match slot(s), ${queue.active.length} active`),
    table("queue", QUEUE_COLUMNS, queue.active.map((e) => [
      e.position === null ? "-" : String(e.position), e.id ?? "-", e.team, e.opponent, e.state,
      when(e.expected_start), e.waiting_reason ?? "-",
    ]), "The queue is empty: no match is waiting or playing. A match asked for now starts at once."),
  );
}

async function standingsPage(root: HTMLElement): Promise<void> {
  let schedule: Schedule;
  try {
    schedule = await getJson<Schedule>("/v1/operator/schedule");
  } catch (error) {
    if (error instanceof PageError && error.message.startsWith("Not found")) {
      root.append(el("h1", {}, "Tournament"), el("p", { "data-testid": "error", class: "error" },
        "No tournament runs on this service: its operator starts one with hlvs schedule run and names its state file in HLVS_SERVICE_SCHEDULE_STATE. The ladder (/watch/ladder) shows the ratings from friendlies."));
      return;
    }
    throw error;
  }
  const standingColumns = ["team", "played", "won", "drawn", "lost", "goals_for", "goals_against", "goal_difference", "points"];
  const labels = ["team", "played", "won", "drawn", "lost", "goals for", "goals against", "goal difference", "points"];
  root.append(
    el("h1", { "data-testid": "standings-title" }, schedule.name ? `${schedule.name}: standings` : "Standings"),
    el("p", {}, el("a", { href: "/watch/tournament", "data-testid": "overview-link" }, "the tournament's live overview")),
    table("standings", ["#", ...labels], schedule.standings.map((s, i) => [String(i + 1), ...standingColumns.map((c) => String(s[c] ?? ""))]),
      "No standings yet: the table fills as the round robin's matches are played."),
    el("h1", {}, "Schedule"),
    table("schedule", ["match", "kind", "red", "blue", "plays at", "state", "score"], schedule.matches.map((m) => {
      const result = m.result as { score?: { red: number; blue: number } } | null;
      return [String(m.id), String(m.kind), String(m.red), String(m.blue), when(String(m.play_at)), String(m.state),
        result?.score ? `${result.score.red} : ${result.score.blue}` : "-"];
    }), "The schedule has no matches."),
  );
}

interface NodeJob {
  job_id: string;
  state: string;
  match_id: string | null;
  submission_id: string | null;
  team: string | null;
  opponent: string | null;
}

interface PoolNode {
  name: string;
  state: string;
  reason: string;
  features: string[];
  cpus: number;
  cpus_allocated: number | null;
  cpu_load: number | null;
  memory_mb: number;
  memory_free_mb: number | null;
  slots: number;
  jobs: NodeJob[];
}

interface PoolNodes {
  pool: string;
  slots: number;
  nodes: PoolNode[];
}

const POOL_REFRESH_MS = 3000;

function describeJob(j: NodeJob): string {
  if (j.submission_id) return `${j.submission_id} (${j.team} v ${j.opponent}) ${j.state}`;
  if (j.match_id) return `match ${j.match_id} (job ${j.job_id}) ${j.state}`;
  return `job ${j.job_id} ${j.state}`;
}

function nodeRows(nodes: PoolNode[]): (string | Node)[][] {
  return nodes.map((n) => [
    n.name, n.state, n.reason || "-", n.features.join(", ") || "-",
    `${n.cpus_allocated === null ? "" : `${n.cpus_allocated}/`}${n.cpus}${n.cpu_load === null ? "" : `, load ${n.cpu_load.toFixed(2)}`}`,
    `${n.memory_mb} MB${n.memory_free_mb === null ? "" : `, ${n.memory_free_mb} free`}`,
    `${n.jobs.length}/${n.slots}`,
    n.jobs.length ? n.jobs.map(describeJob).join("; ") : "-",
  ]);
}

async function poolSection(): Promise<HTMLElement> {
  const [queue, pool] = await Promise.all([getJson<Queue>("/v1/operator/queue"), getJson<PoolNodes>("/v1/operator/nodes")]);
  const running = queue.active.filter((s) => s.state === "running" || s.state === "starting");
  const down = pool.nodes.filter((n) => n.reason !== "").length;
  const nodes = table("nodes", ["node", "state", "reason", "features", "CPUs", "memory", "matches", "running"], nodeRows(pool.nodes),
    "The pool reports no nodes: no match can start until one is up.");
  if (nodes instanceof HTMLTableElement) pool.nodes.forEach((n, i) => { if (n.reason !== "") nodes.rows[i + 1].classList.add("down"); });
  return el("div", { "data-testid": "pool-section" },
    el("p", { "data-testid": "pool-summary" }, `${queue.slots} match slot(s), ${running.length} in use${queue.paused ? ", queue paused" : ""}`),
    table("pool", ["slot", "submission", "team", "state", "started"], running.map((s, i) => [String(i + 1), s.id, s.team, s.state, when(s.started_at)]),
      "No match is playing now."),
    el("h2", {}, `Nodes (${pool.pool} pool)`),
    el("p", { "data-testid": "nodes-summary" }, `${pool.nodes.length} node(s), ${down} out of service`),
    nodes,
    el("p", { class: "muted", "data-testid": "pool-updated" }, `updated ${new Date().toISOString().slice(11, 19)} UTC`),
  );
}

/** The pool for operators: slots in use and the pool's nodes, refreshed every few seconds. */
async function poolPage(root: HTMLElement): Promise<void> {
  let section = await poolSection();
  root.append(el("h1", {}, "Pool"), section);
  const refresh = async (): Promise<void> => {
    try {
      const next = await poolSection();
      section.replaceWith(next);
      section = next;
    } catch (error) {
      section.querySelector("[data-testid=pool-updated]")!.textContent = `not updated: ${String(error)}`;
    }
    setTimeout(() => void refresh(), POOL_REFRESH_MS);
  };
  setTimeout(() => void refresh(), POOL_REFRESH_MS);
}

const OPERATOR_PAGES: Record<string, string> = { standings: "the tournament", schedule: "the tournament", nodes: "the pool" };

export async function tablePage(root: HTMLElement, page: string, arg?: string, who: Who | null = null): Promise<void> {
  const health = await fetch("/v1/health");
  if (health.status === 404) {
    root.append(el("p", { class: "error", "data-testid": "error" },
      "This page is part of hlvs serve (the submission service); hlvs view shows replays and live matches only."));
    return;
  }
  if (page in OPERATOR_PAGES && who?.scope !== "operator") {
    root.append(el("p", { class: "error", "data-testid": "error" },
      `The page of ${OPERATOR_PAGES[page]} is for the league's operators. Your team sees its matches, the queue and the ladder.`));
    return;
  }
  if (page === "submissions") await submissionsPage(root, who);
  else if (page === "queue") await queuePage(root);
  else if (page === "standings" || page === "schedule") await standingsPage(root);
  else await poolPage(root);
}
