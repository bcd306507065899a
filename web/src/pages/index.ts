// The index: replays and live matches this server knows.
import { el, getJson } from "../ui";

interface Listing {
  replays: { id: string; match_id: string; duration_ms: number; version: number }[];
  live: { id: string }[];
}

export async function indexPage(root: HTMLElement, api: string): Promise<void> {
  const listing = await getJson<Listing>(`${api}/index`);
  root.append(
    el("h1", {}, "hlvs-runner"),
    el("h2", {}, "Live"),
    el("ul", { "data-testid": "live-list" }, ...listing.live.map((m) => el("li", {}, el("a", { href: `/watch/live/${encodeURIComponent(m.id)}` }, m.id)))),
    el("h2", {}, "Replays"),
    el("ul", { "data-testid": "replay-list" }, ...listing.replays.map((r) =>
      el("li", {}, el("a", { href: `/watch/replay/${encodeURIComponent(r.id)}` }, `${r.match_id} (${Math.round(r.duration_ms / 1000)} s, format ${r.version})`)))),
  );
}
