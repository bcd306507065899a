// The ladder (/watch/ladder: the table, best rating first) and a team's page
// (/watch/ladder/<team>: its rating history and rated matches, with links to the replays of
// friendlies), read from the service's /v1/ladder with the session's token, under the same
// navigation as every other page.
import { PageError, el, getJson, table } from "../ui";

interface LadderRow {
  rank: number; team: string; rating: number; mu: number; sigma: number; played: number;
  won: number; drawn: number; lost: number; goals_for: number; goals_against: number;
}

interface Ladder { ladder_every_s: number; matches_rated: number; teams: LadderRow[] }

interface LadderMatch {
  played_at: string | null; source: string; opponent: string; goals_for: number;
  goals_against: number; outcome: string; rating_before: number; rating_after: number;
  replay_url: string | null;
}

interface TeamHistory { team: LadderRow; history: { rating: number }[]; matches: LadderMatch[] }

const fixed = (x: number): string => Number(x).toFixed(2);
const when = (iso: string | null): string =>
  iso ? new Date(iso).toISOString().replace("T", " ").slice(0, 16) + " UTC" : "-";
const teamLink = (name: string): HTMLElement => el("a", { href: `/watch/ladder/${encodeURIComponent(name)}` }, name);

function numeric(t: HTMLElement, columns: number[]): HTMLElement {
  if (t instanceof HTMLTableElement) {
    for (const row of Array.from(t.rows)) for (const i of columns) row.cells[i]?.classList.add("num");
  }
  return t;
}

async function board(root: HTMLElement): Promise<void> {
  const ladder = await getJson<Ladder>("/v1/ladder");
  const every = ladder.ladder_every_s > 0
    ? `The ladder plays a friendly between two teams of similar rating at most every ${ladder.ladder_every_s} s, when a match slot is free.`
    : "The ladder schedules no friendlies now; friendlies the teams play are rated.";
  root.append(
    el("h1", {}, "Ladder"),
    el("p", { "data-testid": "ladder-summary" }, `${ladder.matches_rated} match(es) rated. The rating is OpenSkill's mu - 3 sigma. ${every}`),
    numeric(table("ladder", ["#", "team", "rating", "mu", "sigma", "played", "won", "drawn", "lost", "goals"],
      ladder.teams.map((t) => [String(t.rank), teamLink(t.team), fixed(t.rating), fixed(t.mu), fixed(t.sigma),
        String(t.played), String(t.won), String(t.drawn), String(t.lost), `${t.goals_for}:${t.goals_against}`]),
      "No team is on the ladder yet: teams that accept friendlies appear here."), [0, 2, 3, 4, 5, 6, 7, 8]),
  );
}

function chart(history: { rating: number }[]): SVGSVGElement {
  const width = 480, height = 160, pad = 24;
  const values = history.map((p) => p.rating);
  const low = Math.min(...values), high = Math.max(...values);
  const span = high - low || 1;
  const x = (i: number): number => pad + (history.length > 1 ? (i * (width - 2 * pad)) / (history.length - 1) : 0);
  const y = (v: number): number => height - pad - ((v - low) * (height - 2 * pad)) / span;
  const ns = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(ns, "svg");
  for (const [k, v] of [["class", "history"], ["data-testid", "ladder-history"], ["width", String(width)], ["height", String(height)]]) svg.setAttribute(k, v);
  const line = document.createElementNS(ns, "polyline");
  for (const [k, v] of [["fill", "none"], ["stroke", "#2a6"], ["stroke-width", "2"]]) line.setAttribute(k, v);
  line.setAttribute("points", values.map((v, i) => `${x(i)},${y(v)}`).join(" "));
  svg.append(line);
  for (const v of values.length ? [high, low] : []) {
    const text = document.createElementNS(ns, "text");
    text.setAttribute("x", "2");
    text.setAttribute("y", String(y(v) - 2));
    text.setAttribute("font-size", "10");
    text.textContent = fixed(v);
    svg.append(text);
  }
  return svg;
}

async function teamPage(root: HTMLElement, name: string): Promise<void> {
  let team: TeamHistory;
  try {
    team = await getJson<TeamHistory>(`/v1/ladder/${encodeURIComponent(name)}`);
  } catch (error) {
    if (error instanceof PageError && error.status === 404) throw new PageError("There is no such team on the ladder.", 404);
    throw error;
  }
  const t = team.team;
  root.append(
    el("h1", {}, t.team),
    el("p", { "data-testid": "ladder-team" },
      `Rank ${t.rank}, rating ${fixed(t.rating)} (mu ${fixed(t.mu)}, sigma ${fixed(t.sigma)}); ${t.won} won, ${t.drawn} drawn, ${t.lost} lost, goals ${t.goals_for}:${t.goals_against}. `,
      el("a", { href: "/watch/ladder" }, "the ladder")),
    el("h2", {}, "Rating"),
    team.history.length ? chart(team.history) : el("p", { class: "empty" }, "No rating yet: it starts with the team's first rated match."),
    el("h2", {}, "Matches"),
    numeric(table("ladder-matches", ["played", "match", "opponent", "score", "outcome", "rating", "replay"],
      team.matches.map((m) => [when(m.played_at), m.source, teamLink(m.opponent), `${m.goals_for}:${m.goals_against}`, m.outcome,
        `${fixed(m.rating_before)} \u2192 ${fixed(m.rating_after)}`, m.replay_url ? el("a", { href: m.replay_url }, "replay") : "-"]),
      "No rated match yet."), [5]),
  );
}

export async function ladderPage(root: HTMLElement, team?: string): Promise<void> {
  if (team) await teamPage(root, team);
  else await board(root);
}
