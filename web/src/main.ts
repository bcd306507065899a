// Entry point: one bundle for every page; the path after /watch picks the page.
import { livePage } from "./pages/live";
import { indexPage } from "./pages/index";
import { replayPage } from "./pages/replay";
import { tablePage } from "./pages/tables";
import { TOURNAMENT_API, tournamentPage } from "./pages/tournament";
import { el, tokenBox } from "./ui";

const API = "/api/viewer";

async function route(): Promise<void> {
  const root = document.getElementById("app")!;
  const nav = document.querySelector("nav");
  if (nav) tokenBox(nav);
  const parts = location.pathname.replace(/^\/watch\/?/, "").split("/").filter(Boolean).map(decodeURIComponent);
  try {
    if (parts[0] === "tournament" && parts[1] === "replay" && parts[2]) await replayPage(root, TOURNAMENT_API, parts[2]);
    else if (parts[0] === "tournament" && parts[1] === "live" && parts[2]) livePage(root, TOURNAMENT_API, parts[2], "/watch/tournament/replay");
    else if (parts[0] === "tournament") await tournamentPage(root);
    else if (parts[0] === "replay" && parts[1]) await replayPage(root, API, parts[1]);
    else if (parts[0] === "live" && parts[1]) livePage(root, API, parts[1]);
    else if (parts[0] && ["queue", "standings", "schedule", "nodes", "submissions"].includes(parts[0])) await tablePage(root, parts[0], parts[1]);
    else await indexPage(root, API);
  } catch (error) {
    root.append(el("p", { class: "error", "data-testid": "error" }, String(error)));
  }
}

void route();
