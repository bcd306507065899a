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

export class Scoreboard {
  readonly root = el("div", { class: "scoreboard", "data-testid": "scoreboard" });
  private readonly red = el("span", { class: "score red", "data-testid": "score-red" }, "0");
  private readonly blue = el("span", { class: "score blue", "data-testid": "score-blue" }, "0");
  // before the first state arrives: the game has not started (no "-" and "--:--" placeholders)
  private readonly state = el("span", { class: "state", "data-testid": "game-state" }, "not started");
  private readonly clockText = el("span", { class: "clock", "data-testid": "game-clock" }, "");

  constructor(title: string) {
    this.root.append(
      el("span", { class: "title" }, title),
      el("span", { class: "team red" }, "RED"),
      this.red,
      el("span", { class: "colon" }, ":"),
      this.blue,
      el("span", { class: "team blue" }, "BLUE"),
      this.state,
      this.clockText,
    );
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

const TOKEN_KEY = "hlvs-token";

/** The service token the user entered (hlvs serve); none for hlvs view. */
export function authHeaders(): Record<string, string> {
  const token = localStorage.getItem(TOKEN_KEY);
  return token ? { Authorization: `Bearer ${token}` } : {};
}

export function authFetch(url: string): Promise<Response> {
  return fetch(url, { headers: authHeaders() });
}

/** A token box in the navigation bar: kept in this browser's local storage. */
export function tokenBox(nav: HTMLElement): void {
  const input = el("input", { type: "password", placeholder: "service token", "data-testid": "token", size: "28" });
  input.value = localStorage.getItem(TOKEN_KEY) ?? "";
  const save = el("button", { "data-testid": "token-save" }, "use token");
  save.addEventListener("click", () => {
    if (input.value) localStorage.setItem(TOKEN_KEY, input.value.trim());
    else localStorage.removeItem(TOKEN_KEY);
    location.reload();
  });
  nav.append(el("span", { class: "token" }, input, save));
}

export async function getJson<T>(url: string): Promise<T> {
  const response = await authFetch(url);
  if (!response.ok) throw new Error(`${url}: ${response.status} ${await response.text()}`);
  return (await response.json()) as T;
}
