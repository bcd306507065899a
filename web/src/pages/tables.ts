// Service pages (queue, schedule and standings, submissions, pool nodes): tables filled from the
// submission service's API. Placeholder until the service routes are wired in.
import { el } from "../ui";

export async function tablePage(root: HTMLElement, page: string, _arg?: string): Promise<void> {
  root.append(el("h1", {}, page), el("p", { "data-testid": "error" }, "this page needs hlvs serve"));
}
