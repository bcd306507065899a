// The operator's live overview of the tournament (/watch/tournament): every match with its
// state, score (the clock while it runs), log delivery, links to the live view and the replay;
// the knockout bracket and the standings with their tie-breaks. Refreshed every few seconds.
import { el, getJson } from "../ui";
import { table } from "./tables";

export const TOURNAMENT_API = "/api/tournament";
const REFRESH_MS = 3000;

interface TeamLogs { team: string; state: string; cause: string; attempts: number }

interface Match {
  id: string;
  kind: string;
  state: string;
  red: string;
  blue: string;
  play_at: string;
  stream_start: string;
  attempts: number;
  note: string;
  played: boolean;
  logs_delivered: boolean;
  logs: TeamLogs[];
  result: { winner_team?: string | null } | null;
  score_text: string;
  clock_text: string;
  watch: { live?: string; replay?: string };
}

interface Standing {
  team: string; played: number; won: number; drawn: number; lost: number; goals_for: number;
  goals_against: number; goal_difference: number; points: number; decided_by: string;
}

interface Tournament {
  name: string;
  updated_at: string;
  matches: Match[];
  standings: Standing[];
  bracket: string[][];
  warnings: string[];
}

function when(iso: string): string {
  return new Date(iso).toISOString().replace("T", " ").slice(0, 16) + " UTC";
}

function logsCell(m: Match): Node {
  if (!m.played) return document.createTextNode("-");
  if (!m.logs.length) return el("span", { class: "logs pending" }, "pending");
  return el("span", {}, ...m.logs.map((l) => el("span", {
    class: `logs ${l.state}`, title: l.cause, "data-team": l.team, "data-state": l.state,
  }, `${l.team}: ${l.state}${l.attempts > 1 ? ` (${l.attempts} attempts)` : ""}${l.cause && l.state !== "delivered" ? ` - ${l.cause}` : ""} `)));
}

function watchCell(m: Match): Node {
  const links = el("span", {});
  if (m.watch.live) links.append(el("a", { href: m.watch.live, "data-testid": `live-${m.id}` }, "live"), " ");
  if (m.watch.replay) links.append(el("a", { href: m.watch.replay, "data-testid": `replay-${m.id}` }, "replay"));
  return links;
}

function matchRows(matches: Match[]): (string | Node)[][] {
  return matches.map((m) => [
    m.id, m.kind === "knockout" ? "knockout" : "round robin", m.red, m.blue, when(m.play_at), when(m.stream_start),
    m.state, m.played ? (m.logs_delivered ? "played, logs delivered" : "played") : "-",
    m.state === "PLAYING" ? (m.clock_text || "playing") : (m.score_text || "-"),
    logsCell(m), String(m.attempts), m.note || "-", watchCell(m),
  ]);
}

function bracketSection(t: Tournament): HTMLElement {
  const byId = new Map(t.matches.map((m) => [m.id, m]));
  const rounds = t.bracket.map((ids, i) => el("div", { class: "round", "data-testid": `round-${i + 1}` },
    el("h3", {}, i === t.bracket.length - 1 ? "Final round" : `Round ${i + 1}`),
    ...ids.map((id) => {
      const m = byId.get(id);
      const winner = m?.result?.winner_team ?? null;
      return el("div", { class: "tie", "data-match": id },
        el("div", { class: winner === m?.red ? "winner" : "" }, m?.red ?? "?"),
        el("div", { class: winner === m?.blue ? "winner" : "" }, m?.blue ?? "?"),
        el("div", { class: "muted" }, `${id}: ${m?.score_text || m?.state || ""}`));
    })));
  return el("div", { class: "bracket", "data-testid": "bracket" }, ...rounds);
}

const STANDING_COLUMNS = ["#", "team", "played", "won", "drawn", "lost", "goals for", "goals against", "goal difference", "points", "tie-break"];

function standingRows(standings: Standing[]): string[][] {
  return standings.map((s, i) => [
    String(i + 1), s.team, String(s.played), String(s.won), String(s.drawn), String(s.lost), String(s.goals_for),
    String(s.goals_against), String(s.goal_difference), String(s.points), s.decided_by ? `above the next by ${s.decided_by}` : "",
  ]);
}

async function section(): Promise<HTMLElement> {
  const t = await getJson<Tournament>("/v1/operator/tournament");
  const running = t.matches.filter((m) => m.state === "PLAYING").length;
  const parts: HTMLElement[] = [
    el("h1", { "data-testid": "tournament-name" }, t.name),
    el("p", { "data-testid": "tournament-summary" },
      `${t.matches.length} matches, ${running} playing, ${t.matches.filter((m) => m.played).length} played, ` +
      `${t.matches.filter((m) => m.logs_delivered).length} with every log delivered`),
  ];
  if (t.warnings.length) parts.push(el("ul", { class: "warnings", "data-testid": "warnings" }, ...t.warnings.map((w) => el("li", {}, w))));
  parts.push(el("h2", {}, "Matches"), table("tournament-matches", [
    "match", "kind", "red", "blue", "plays at", "stream", "state", "played", "score", "logs", "attempts", "note", "watch",
  ], matchRows(t.matches), "The schedule has no matches yet."));
  if (t.bracket.length) parts.push(el("h2", {}, "Bracket"), bracketSection(t));
  if (t.standings.some((s) => s.played > 0)) {
    parts.push(el("h2", {}, "Standings"), table("tournament-standings", STANDING_COLUMNS, standingRows(t.standings)),
      el("p", { class: "muted" }, "3 points a win, 1 a draw; level on points: head-to-head, then goal difference, goals scored, a drawing of lots."));
  }
  parts.push(el("p", { class: "muted", "data-testid": "tournament-updated" }, `updated ${t.updated_at.slice(11, 19)} UTC (every ${REFRESH_MS / 1000} s)`));
  return el("div", { "data-testid": "tournament" }, ...parts);
}

/** The overview, replaced by a fresh one every REFRESH_MS (an error is shown, the old kept). */
export async function tournamentPage(root: HTMLElement): Promise<void> {
  let current = await section();
  root.append(current);
  const refresh = async (): Promise<void> => {
    try {
      const next = await section();
      current.replaceWith(next);
      current = next;
    } catch (error) {
      current.querySelector("[data-testid=tournament-updated]")!.textContent = `not updated: ${String(error)}`;
    }
    setTimeout(() => void refresh(), REFRESH_MS);
  };
  setTimeout(() => void refresh(), REFRESH_MS);
}
