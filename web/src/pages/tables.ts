// Service pages, filled from hlvs serve's /v1 API with the token of the navigation bar:
// a team's submissions (queue position, expected start, why it waits, results, replay and live
// links), the operator's queue, the tournament schedule and standings, and the pool.
import { el, getJson } from "../ui";

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

export function table(testid: string, columns: string[], rows: (string | Node)[][]): HTMLTableElement {
  return el("table", { "data-testid": testid },
    el("tr", {}, ...columns.map((c) => el("th", {}, c))),
    ...rows.map((cells) => el("tr", {}, ...cells.map((c) => el("td", {}, c)))));
}

function watchLinks(s: Submission): Node {
  const links = el("span", {});
  if (s.state === "running") links.append(el("a", { href: `/watch/live/${encodeURIComponent(s.id)}` }, "live"), " ");
  if (s.state === "done" || s.state === "failed") links.append(el("a", { href: `/watch/replay/${encodeURIComponent(s.id)}` }, "replay"));
  return links;
}

function queueRows(active: Submission[]): (string | Node)[][] {
  return active.map((s) => [
    s.queue_position === null ? "-" : String(s.queue_position), s.id, s.team, s.opponent, s.state,
    when(s.expected_start), s.waiting_reason ?? "-",
  ]);
}

const QUEUE_COLUMNS = ["position", "submission", "team", "opponent", "state", "expected start", "reason"];

async function score(s: Submission): Promise<string> {
  if (s.state !== "done") return "-";
  try {
    const results = await getJson<{ score?: { red: number; blue: number } }>(`/v1/submissions/${encodeURIComponent(s.id)}/results`);
    return results.score ? `${s.team} ${results.score.red} : ${results.score.blue} ${s.opponent}` : "-";
  } catch {
    return "-";
  }
}

async function submissionsPage(root: HTMLElement): Promise<void> {
  const rows = await getJson<Submission[]>("/v1/submissions");
  const scores = await Promise.all(rows.map(score));
  root.append(el("h1", {}, "Your test matches"), table("submissions", [
    "submission", "opponent", "state", "queue position", "expected start", "reason", "finished", "result", "outcome", "watch",
  ], rows.map((s, i) => [
    s.id, s.opponent, s.state, s.queue_position === null ? "-" : String(s.queue_position), when(s.expected_start),
    s.waiting_reason ?? "-", when(s.finished_at), scores[i],
    s.failure_class ? `${s.failure_class}: ${s.cause ?? ""}` : (s.cause ?? "-"), watchLinks(s),
  ])));
}

async function queuePage(root: HTMLElement): Promise<void> {
  const queue = await getJson<Queue>("/v1/operator/queue");
  root.append(
    el("h1", {}, "Queue"),
    el("p", { "data-testid": "queue-summary" }, `${queue.paused ? "paused" : "running"}, ${queue.slots} match slot(s), ${queue.active.length} active`),
    table("queue", QUEUE_COLUMNS, queueRows(queue.active)),
  );
}

async function standingsPage(root: HTMLElement): Promise<void> {
  const schedule = await getJson<Schedule>("/v1/operator/schedule");
  const standingColumns = ["team", "played", "won", "drawn", "lost", "goals_for", "goals_against", "goal_difference", "points"];
  const labels = ["team", "played", "won", "drawn", "lost", "goals for", "goals against", "goal difference", "points"];
  root.append(
    el("h1", { "data-testid": "standings-title" }, schedule.name ? `${schedule.name}: standings` : "Standings"),
    el("p", {}, el("a", { href: "/watch/tournament", "data-testid": "overview-link" }, "the tournament's live overview")),
    table("standings", ["#", ...labels], schedule.standings.map((s, i) => [String(i + 1), ...standingColumns.map((c) => String(s[c] ?? ""))])),
    el("h1", {}, "Schedule"),
    table("schedule", ["match", "kind", "red", "blue", "plays at", "state", "score"], schedule.matches.map((m) => {
      const result = m.result as { score?: { red: number; blue: number } } | null;
      return [String(m.id), String(m.kind), String(m.red), String(m.blue), when(String(m.play_at)), String(m.state),
        result?.score ? `${result.score.red} : ${result.score.blue}` : "-"];
    })),
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
  const nodes = table("nodes", ["node", "state", "reason", "features", "CPUs", "memory", "matches", "running"], nodeRows(pool.nodes));
  pool.nodes.forEach((n, i) => { if (n.reason !== "") nodes.rows[i + 1].classList.add("down"); });
  return el("div", { "data-testid": "pool-section" },
    el("p", { "data-testid": "pool-summary" }, `${queue.slots} match slot(s), ${running.length} in use${queue.paused ? ", queue paused" : ""}`),
    table("pool", ["slot", "submission", "team", "state", "started"], running.map((s, i) => [String(i + 1), s.id, s.team, s.state, when(s.started_at)])),
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

export async function tablePage(root: HTMLElement, page: string, _arg?: string): Promise<void> {
  const health = await fetch("/v1/health");
  if (health.status === 404) {
    root.append(el("p", { class: "error", "data-testid": "error" },
      "This page is part of hlvs serve (the submission service); hlvs view shows replays and live matches only."));
    return;
  }
  if (page === "submissions") await submissionsPage(root);
  else if (page === "queue") await queuePage(root);
  else if (page === "standings" || page === "schedule") await standingsPage(root);
  else await poolPage(root);
}
