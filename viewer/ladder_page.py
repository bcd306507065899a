"""The ladder's pages inside ``hlvs serve``: ``/watch/ladder`` (the table, best rating first) and
``/watch/ladder/<team>`` (the team's rating history and its rated matches, with links to the
replays of friendlies).

A small page of its own, filled in the browser from ``/v1/ladder`` with the service token that
the viewer's pages keep in the browser (the token box of the navigation bar). An error is shown
as a sentence (the API's ``message``), never as the raw answer. Mounted by ``hlvs.app`` before
the viewer, whose ``/watch/...`` pages would otherwise take the path.
"""

from __future__ import annotations

from fastapi import APIRouter, FastAPI
from fastapi.responses import HTMLResponse

router = APIRouter()

PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>hlvs-runner: ladder</title>
<link rel="stylesheet" href="/watch/static/style.css">
<style>
  table.ladder td.num, table.ladder th.num { text-align: right; }
  svg.history { background: #fafafa; border: 1px solid #ddd; }
</style>
</head>
<body>
<nav><a href="/watch/">matches</a> <a href="/watch/queue">queue</a>
<a href="/watch/standings">standings</a> <a href="/watch/ladder">ladder</a>
<a href="/watch/submissions">submissions</a> <a href="/watch/nodes">pool</a>
<span class="token"><input type="password" placeholder="service token" data-testid="token"
size="28"> <button data-testid="token-save">use token</button></span></nav>
<main id="app"></main>
<script>
"use strict";
const KEY = "hlvs-token";
const app = document.getElementById("app");
const box = document.querySelector("[data-testid=token]");
box.value = sessionStorage.getItem(KEY) || localStorage.getItem(KEY) || "";
document.querySelector("[data-testid=token-save]").addEventListener("click", () => {
  if (box.value.trim()) sessionStorage.setItem(KEY, box.value.trim());
  else sessionStorage.removeItem(KEY);
  location.reload();
});

function el(tag, attrs, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  for (const c of children) node.append(c instanceof Node ? c : String(c));
  return node;
}

function fail(sentence) {
  app.append(el("p", { class: "error", "data-testid": "error" }, sentence));
}

async function load(url) {
  const token = box.value.trim();
  let response;
  try {
    response = await fetch(url, { headers: token ? { Authorization: "Bearer " + token } : {} });
  } catch (error) {
    throw new Error("The service could not be reached; try again in a moment.");
  }
  if (response.ok) return response.json();
  let message = "";
  try { message = (await response.json()).message || ""; } catch (error) { message = ""; }
  if (response.status === 401 || response.status === 403) {
    throw new Error("The ladder needs a team or operator token: enter it in the box above."
                    + (message ? " (" + message + ".)" : ""));
  }
  if (response.status === 404) throw new Error("There is no such team on the ladder.");
  throw new Error("The service could not answer (" + response.status + ")"
                  + (message ? ": " + message : "") + ".");
}

function table(testid, columns, rows) {
  const head = el("tr", {}, ...columns.map(([name, cls]) => el("th", { class: cls || "" }, name)));
  return el("table", { class: "ladder", "data-testid": testid }, head,
    ...rows.map((cells) => el("tr", {}, ...cells.map((c, i) =>
      el("td", { class: columns[i][1] || "" }, c)))));
}

const fixed = (x) => Number(x).toFixed(2);
const when = (iso) =>
  iso ? new Date(iso).toISOString().replace("T", " ").slice(0, 16) + " UTC" : "-";
const teamLink = (name) => el("a", { href: "/watch/ladder/" + encodeURIComponent(name) }, name);

async function ladderPage() {
  const ladder = await load("/v1/ladder");
  app.append(el("h1", {}, "Ladder"));
  const every = ladder.ladder_every_s > 0
    ? "The ladder plays a friendly between two teams of similar rating at most every "
      + ladder.ladder_every_s + " s, when a match slot is free."
    : "The ladder schedules no friendlies now; friendlies the teams play are rated.";
  app.append(el("p", { "data-testid": "ladder-summary" }, ladder.matches_rated
    + " match(es) rated. The rating is OpenSkill's mu - 3 sigma. " + every));
  if (!ladder.teams.length) {
    app.append(el("p", {},
      "No team is on the ladder yet: teams that accept friendlies appear here."));
    return;
  }
  app.append(table("ladder", [["#", "num"], ["team"], ["rating", "num"], ["mu", "num"],
    ["sigma", "num"], ["played", "num"], ["won", "num"], ["drawn", "num"], ["lost", "num"],
    ["goals", "num"]], ladder.teams.map((t) => [t.rank, teamLink(t.team), fixed(t.rating),
    fixed(t.mu), fixed(t.sigma), t.played, t.won, t.drawn, t.lost,
    t.goals_for + ":" + t.goals_against])));
}

function chart(history) {
  const width = 480, height = 160, pad = 24;
  const values = history.map((p) => p.rating);
  const low = Math.min(...values), high = Math.max(...values);
  const span = high - low || 1;
  const x = (i) => pad + (history.length > 1 ? i * (width - 2 * pad) / (history.length - 1) : 0);
  const y = (v) => height - pad - (v - low) * (height - 2 * pad) / span;
  const ns = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(ns, "svg");
  svg.setAttribute("class", "history");
  svg.setAttribute("data-testid", "ladder-history");
  svg.setAttribute("width", width);
  svg.setAttribute("height", height);
  const line = document.createElementNS(ns, "polyline");
  line.setAttribute("fill", "none");
  line.setAttribute("stroke", "#2a6");
  line.setAttribute("stroke-width", "2");
  line.setAttribute("points", values.map((v, i) => x(i) + "," + y(v)).join(" "));
  svg.append(line);
  for (const [v, label] of [[high, fixed(high)], [low, fixed(low)]]) {
    const text = document.createElementNS(ns, "text");
    text.setAttribute("x", 2);
    text.setAttribute("y", y(v) - 2);
    text.setAttribute("font-size", "10");
    text.textContent = label;
    svg.append(text);
  }
  return svg;
}

async function teamPage(name) {
  const team = await load("/v1/ladder/" + encodeURIComponent(name));
  const t = team.team;
  app.append(el("h1", {}, t.team), el("p", { "data-testid": "ladder-team" },
    "Rank " + t.rank + ", rating " + fixed(t.rating) + " (mu " + fixed(t.mu) + ", sigma "
    + fixed(t.sigma) + "); " + t.won + " won, " + t.drawn + " drawn, " + t.lost + " lost, goals "
    + t.goals_for + ":" + t.goals_against + ". ",
    el("a", { href: "/watch/ladder" }, "the ladder")));
  app.append(el("h2", {}, "Rating"), chart(team.history));
  app.append(el("h2", {}, "Matches"));
  if (!team.matches.length) {
    app.append(el("p", {}, "No rated match yet."));
    return;
  }
  app.append(table("ladder-matches", [["played"], ["match"], ["opponent"], ["score"],
    ["outcome"], ["rating", "num"], ["replay"]], team.matches.map((m) => [
    when(m.played_at), m.source, teamLink(m.opponent), m.goals_for + ":" + m.goals_against,
    m.outcome, fixed(m.rating_before) + " \\u2192 " + fixed(m.rating_after),
    m.replay_url ? el("a", { href: m.replay_url }, "replay") : "-"])));
}

const parts = location.pathname.replace(/^\\/watch\\/ladder\\/?/, "").split("/").filter(Boolean);
(parts.length ? teamPage(decodeURIComponent(parts[0])) : ladderPage())
  .catch((error) => fail(error.message));
</script>
</body>
</html>
"""


@router.get("/watch/ladder", include_in_schema=False)
@router.get("/watch/ladder/{team}", include_in_schema=False)
def ladder_page() -> HTMLResponse:
    return HTMLResponse(PAGE)


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
