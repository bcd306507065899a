// Entry point: one bundle for every page; the path after /watch picks the page. Under hlvs serve
// the pages ask for the token once (kept for the browser session) and the navigation shows what
// the token's role may see; hlvs view needs no sign-in.
import { livePage } from "./pages/live";
import { indexPage } from "./pages/index";
import { replayPage } from "./pages/replay";
import { ladderPage } from "./pages/ladder";
import { tablePage } from "./pages/tables";
import { TOURNAMENT_API, tournamentPage } from "./pages/tournament";
import { type Who, el, signInForm, signOut, token, whoAmI } from "./ui";

const API = "/api/viewer";
const SERVICE_PAGES = ["queue", "standings", "schedule", "nodes", "submissions"];

/** The navigation links of a role (hlvs view: the matches only). */
export function navLinks(who: Who | null, service: boolean): [string, string][] {
  if (!service) return [["/watch/", "matches"]];
  const links: [string, string][] = [
    ["/watch/", "live and replays"],
    ["/watch/submissions", who?.scope === "operator" ? "all matches" : "our matches"],
    ["/watch/queue", "queue"],
    ["/watch/ladder", "ladder"],
  ];
  if (who?.scope === "operator") links.push(["/watch/tournament", "tournament"], ["/watch/standings", "standings"], ["/watch/nodes", "pool"]);
  return links;
}

function navigation(nav: HTMLElement, who: Who | null, service: boolean): void {
  nav.replaceChildren(...navLinks(who, service).map(([href, text]) => el("a", { href }, text)));
  if (who) {
    const out = el("button", { class: "sign-out", "data-testid": "sign-out" }, "sign out");
    out.addEventListener("click", signOut);
    nav.append(el("span", { class: "who", "data-testid": "who" },
      who.scope === "operator" ? "operator" : `team ${who.team ?? ""}`, " ", out));
  }
}

/** GET `url`, tried again when the network fails (a connection the server closed as the
 * browser reused it, a server busy starting): a passing failure is not a blank page. */
async function fetchRetried(url: string, tries = 4): Promise<Response> {
  for (let attempt = 1; ; attempt += 1) {
    try {
      return await fetch(url);
    } catch (error) {
      if (attempt >= tries) throw error;
      await new Promise((resolve) => setTimeout(resolve, 500 * attempt));
    }
  }
}

async function route(): Promise<void> {
  const root = document.getElementById("app")!;
  const nav = document.querySelector("nav");
  let service: boolean;
  try {
    service = (await fetchRetried("/v1/health")).status !== 404;
  } catch (error) {
    root.append(el("p", { class: "error", "data-testid": "error" },
      `The server does not answer (${error instanceof Error ? error.message : String(error)}): reload this page when it is back.`));
    return;
  }
  const who = service ? await whoAmI() : null;
  if (nav) navigation(nav, who, service);
  if (service && !who) {
    signInForm(root, token() ? "Your token is no longer valid. Please sign in again." : "");
    return;
  }
  const parts = location.pathname.replace(/^\/watch\/?/, "").split("/").filter(Boolean).map(decodeURIComponent);
  try {
    if (parts[0] === "tournament" && parts[1] === "replay" && parts[2]) await replayPage(root, TOURNAMENT_API, parts[2], "/watch/tournament");
    else if (parts[0] === "tournament" && parts[1] === "live" && parts[2]) livePage(root, TOURNAMENT_API, parts[2], "/watch/tournament/replay");
    else if (parts[0] === "tournament") await tournamentPage(root);
    else if (parts[0] === "replay" && parts[1]) await replayPage(root, API, parts[1]);
    else if (parts[0] === "live" && parts[1]) livePage(root, API, parts[1]);
    else if (parts[0] === "ladder" && service) await ladderPage(root, parts[1]);
    else if (parts[0] && SERVICE_PAGES.includes(parts[0])) await tablePage(root, parts[0], parts[1], who);
    else await indexPage(root, API);
  } catch (error) {
    root.append(el("p", { class: "error", "data-testid": "error" }, error instanceof Error ? error.message : String(error)));
  }
}

void route();
