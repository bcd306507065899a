// Small DOM helpers shared by the pages: elements, the scoreboard, time formatting.
import type { GameState } from "./replay";

export function el<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Record<string, string> = {},
  ...children: (Node | string)[]
): HTMLElementTagNameMap[K] {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  for (const child of children) node.append(child);
  return node;
}

export function clock(ms: number): string {
  const s = Math.max(0, Math.floor(ms / 1000));
  return `${String(Math.floor(s / 60)).padStart(2, "0")}:${String(s % 60).padStart(2, "0")}`;
}

/** Set a node's text only when it differs (a write, even of the same text, costs a layout). */
export function setText(node: Node, text: string): void {
  if (node.textContent !== text) node.textContent = text;
}

/** The teams' names a page was linked with (`?red=ants&blue=bees`). */
export function teamNames(): { red: string | null; blue: string | null } {
  const query = new URLSearchParams(location.search);
  return { red: query.get("red"), blue: query.get("blue") };
}

/** The teams' names of a match (the viewer API's `teams`), when known. */
export interface TeamNames { red?: string | null; blue?: string | null }

export class Scoreboard {
  readonly root = el("div", { class: "scoreboard", "data-testid": "scoreboard" });
  private readonly redName: HTMLElement;
  private readonly blueName: HTMLElement;
  private readonly red = el("span", { class: "score red", "data-testid": "score-red" }, "0");
  private readonly blue = el("span", { class: "score blue", "data-testid": "score-blue" }, "0");
  // before the first state arrives: the game has not started (no "-" and "--:--" placeholders)
  private readonly state = el("span", { class: "state", "data-testid": "game-state" }, "not started");
  private readonly clockText = el("span", { class: "clock", "data-testid": "game-clock" }, "");

  /** `names`: the teams' names (default: the page's `?red=...&blue=...`, else RED and BLUE). */
  constructor(title: string, names: TeamNames | null = null) {
    this.redName = el("span", { class: "team red", "data-testid": "team-red", title: "red" });
    this.blueName = el("span", { class: "team blue", "data-testid": "team-blue", title: "blue" });
    this.setNames(names);
    this.root.append(
      el("span", { class: "title" }, title),
      this.redName,
      this.red,
      el("span", { class: "colon" }, ":"),
      this.blue,
      this.blueName,
      this.state,
      this.clockText,
    );
  }

  /** The teams' names, as the server knows them; else those the page was linked with. */
  setNames(names: TeamNames | null): void {
    const linked = teamNames();
    setText(this.redName, names?.red || linked.red || "RED");
    setText(this.blueName, names?.blue || linked.blue || "BLUE");
  }

  /** Called every frame: touches the page only where a text changed (no layout otherwise). */
  update(game: GameState | null | undefined): void {
    if (!game) return;
    const score = game.score;
    if (score) {
      setText(this.red, String(score.red));
      setText(this.blue, String(score.blue));
    }
    const half = game.half === 1 ? "1st half" : game.half === 2 ? "2nd half" : "";
    const secondary = game.secondary_state && game.secondary_state !== "NORMAL" ? ` ${game.secondary_state}` : "";
    setText(this.state, `${game.state ?? "not started"}${secondary} ${half}`.trim());
    if (typeof game.secs_remaining === "number") setText(this.clockText, clock(game.secs_remaining * 1000));
  }
}

export function describeEvent(e: { type: string; team?: string | null; player?: number | null; reason?: string }): string {
  const who = e.team ? ` ${e.team}${e.player ? ` ${e.player}` : ""}` : "";
  return `${e.type}${who}${e.reason ? `: ${e.reason}` : ""}`;
}

// --- sign-in -------------------------------------------------------------------------------
// hlvs serve's pages ask for the token once and keep it for this browser session (session
// storage: gone when the browser closes); every page then shows what the token's role may see.
const TOKEN_KEY = "hlvs-token";

export interface Who {
  scope: "team" | "operator";
  team: string | null;
}

export function token(): string | null {
  return sessionStorage.getItem(TOKEN_KEY);
}

/** The service token of this browser session (hlvs serve); none for hlvs view. */
export function authHeaders(): Record<string, string> {
  const value = token();
  return value ? { Authorization: `Bearer ${value}` } : {};
}

export function authFetch(url: string): Promise<Response> {
  return fetch(url, { headers: authHeaders() });
}

export function signOut(): void {
  sessionStorage.removeItem(TOKEN_KEY);
  location.reload();
}

/** The sign-in form: the token is checked with the service before it is kept. */
export function signInForm(root: HTMLElement, reason = ""): void {
  const input = el("input", { type: "password", placeholder: "your token (hlvs_...)", "data-testid": "token", size: "40", autocomplete: "current-password" });
  const go = el("button", { type: "submit", "data-testid": "sign-in" }, "Sign in");
  const message = el("p", { class: "error", "data-testid": "error" }, reason);
  const form = el("form", { class: "sign-in", "data-testid": "sign-in-form" },
    el("h1", {}, "Sign in"),
    el("p", {}, "Enter the token the league gave your team (or your operator token). It is kept until you close the browser."),
    input, " ", go, message);
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    void (async () => {
      const value = input.value.trim();
      const answer = await fetch("/v1/whoami", { headers: { Authorization: `Bearer ${value}` } });
      if (!answer.ok) {
        message.textContent = await sentence(answer, "/v1/whoami");
        return;
      }
      sessionStorage.setItem(TOKEN_KEY, value);
      location.reload();
    })();
  });
  root.replaceChildren(form);
}

/** Who the session's token speaks for; null without a token or when it is not valid. */
export async function whoAmI(): Promise<Who | null> {
  if (!token()) return null;
  const answer = await authFetch("/v1/whoami");
  if (!answer.ok) return null;
  return (await answer.json()) as Who;
}

/** An answer that is not OK, as a sentence for a person (never the raw JSON). */
export async function sentence(response: Response, url: string): Promise<string> {
  let message = "";
  try {
    const body = (await response.json()) as { message?: unknown };
    message = typeof body.message === "string" ? body.message : "";
  } catch {
    message = "";
  }
  if (response.status === 401 && message.includes("needs an operator token")) {
    return "This page is for the league's operators; your team's token does not open it.";
  }
  if (response.status === 401 && message.includes("needs a team token")) {
    return "This page shows one team's data; sign in with a team's token to see it.";
  }
  if (response.status === 401) return "You are not signed in, or your token is no longer valid. Please sign in again.";
  if (response.status === 404) {
    return message ? `Not found: ${message.replace(/^no /, "there is no ")}.` : `Nothing was found at ${url}.`;
  }
  if (response.status >= 500) return "The service could not answer just now. Please try again in a moment.";
  return message ? `The service refused: ${message}.` : `The service answered ${response.status} for ${url}.`;
}

/** An error whose message is a sentence for a person; `status`: the HTTP status behind it. */
export class PageError extends Error {
  constructor(message: string, readonly status = 0) {
    super(message);
  }
}

/** A table, or the sentence `empty` in its place when there is no row (never a bare header). */
export function table(testid: string, columns: string[], rows: (string | Node)[][], empty = ""): HTMLElement {
  if (!rows.length && empty) return el("p", { class: "empty", "data-testid": `${testid}-empty` }, empty);
  return el("table", { "data-testid": testid },
    el("tr", {}, ...columns.map((c) => el("th", {}, c))),
    ...rows.map((cells) => el("tr", {}, ...cells.map((c) => el("td", {}, c)))));
}

export async function getJson<T>(url: string): Promise<T> {
  const response = await authFetch(url);
  if (!response.ok) throw new PageError(await sentence(response, url), response.status);
  return (await response.json()) as T;
}
