// The index: replays and live matches this server knows.
import { type TeamNames, el, getJson } from "../ui";

interface Listing {
  replays: { id: string; match_id: string; duration_ms: number; version: number; teams?: TeamNames | null }[];
  live: { id: string; teams?: TeamNames | null }[];
}

function versus(teams: TeamNames | null | undefined): string {
  return teams?.red && teams.blue ? `${teams.red} v ${teams.blue}: ` : "";
}

function list(testid: string, items: HTMLElement[], empty: string): HTMLElement {
  return items.length ? el("ul", { "data-testid": testid }, ...items) : el("p", { class: "empty", "data-testid": `${testid}-empty` }, empty);
}

export async function indexPage(root: HTMLElement, api: string): Promise<void> {
  const listing = await getJson<Listing>(`${api}/index`);
  root.append(
    el("h1", {}, "hlvs-runner"),
    el("h2", {}, "Live"),
    list("live-list", listing.live.map((m) => el("li", {}, el("a", { href: `/watch/live/${encodeURIComponent(m.id)}` }, `${versus(m.teams)}${m.id}`))),
      "No match is being played now."),
    el("h2", {}, "Replays"),
    list("replay-list", listing.replays.map((r) =>
      el("li", {}, el("a", { href: `/watch/replay/${encodeURIComponent(r.id)}` }, `${versus(r.teams)}${r.match_id} (${Math.round(r.duration_ms / 1000)} s, format ${r.version})`))),
    "No replay yet: a match's replay appears here when it ends."),
  );
}
