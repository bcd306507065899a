// Plots from api_stats.jsonl samples: the real-time factor over time, and per robot the
// bandwidth used (both directions, from the byte counters) and the round-trip latency. The x
// axis is match time (simulated seconds, as the replay's clock), with a playhead at the
// replay's time.
import { TEAM_CSS } from "../scene";
import { el, getJson } from "../ui";

interface Sample {
  real_time_s: number;
  sim_time_ms: number;
  real_time_factor: number;
  robots: Record<string, { bytes_in: number; bytes_out: number; round_trip_ms: number | null; connected: boolean }>;
}

type Series = { name: string; colour: string; points: [number, number][] };

const SVG = "http://www.w3.org/2000/svg";
const SHADES: Record<string, string[]> = {
  red: ["#d91f1a", "#f07a2a", "#c2185b", "#8e2424"],
  blue: ["#1a40e6", "#2aa7f0", "#5e35b1", "#00897b"],
};

/** Red robots in reds, blue robots in blues ("red-2": the second red shade). */
function colourOf(robot: string): string {
  const [team, number] = robot.split(/[-_]/);
  const shades = SHADES[team];
  return shades ? shades[(Number(number) - 1 + shades.length) % shades.length] : TEAM_CSS[team] ?? "#333";
}

const WIDTH = 420;
const HEIGHT = 180;
const PAD = 36;

export function lineChart(title: string, unit: string, series: Series[], testid: string, xmax = 0): HTMLElement {
  const width = WIDTH;
  const height = HEIGHT;
  const pad = PAD;
  const all = series.flatMap((s) => s.points);
  xmax = xmax || Math.max(1, ...all.map((p) => p[0]));
  const ymax = Math.max(1e-9, ...all.map((p) => p[1])) * 1.1;
  const svg = document.createElementNS(SVG, "svg");
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  svg.setAttribute("data-testid", testid);
  const axis = document.createElementNS(SVG, "path");
  axis.setAttribute("d", `M${pad},8 V${height - 20} H${width - 8}`);
  axis.setAttribute("stroke", "#888");
  axis.setAttribute("fill", "none");
  svg.append(axis);
  for (const [y, text] of [[8, ymax.toPrecision(3)], [height - 20, "0"]] as [number, string][]) {
    const label = document.createElementNS(SVG, "text");
    label.setAttribute("x", "2");
    label.setAttribute("y", String(y + 4));
    label.setAttribute("font-size", "10");
    label.textContent = text;
    svg.append(label);
  }
  const xLabel = document.createElementNS(SVG, "text");
  xLabel.setAttribute("x", String(width - 8));
  xLabel.setAttribute("text-anchor", "end");
  xLabel.setAttribute("y", String(height - 4));
  xLabel.setAttribute("font-size", "10");
  xLabel.textContent = `${xmax.toFixed(0)} s (match time)`;
  svg.append(xLabel);
  const head = document.createElementNS(SVG, "line");
  head.setAttribute("class", "playhead");
  head.setAttribute("data-testid", `${testid}-playhead`);
  head.setAttribute("y1", "8");
  head.setAttribute("y2", String(height - 20));
  head.setAttribute("x1", String(pad));
  head.setAttribute("x2", String(pad));
  head.setAttribute("stroke", "#222");
  head.setAttribute("stroke-dasharray", "3 2");
  head.dataset.xmax = String(xmax);
  for (const s of series) {
    const line = document.createElementNS(SVG, "polyline");
    const points = s.points.map(([x, y]) => `${(pad + (x / xmax) * (width - pad - 8)).toFixed(1)},${(height - 20 - (y / ymax) * (height - 28)).toFixed(1)}`);
    line.setAttribute("points", points.join(" "));
    line.setAttribute("stroke", s.colour);
    line.setAttribute("fill", "none");
    line.setAttribute("stroke-width", "1.5");
    line.setAttribute("data-series", s.name);
    svg.append(line);
  }
  svg.append(head);
  const legend = el("div", { class: "legend" }, ...series.map((s) => el("span", { style: `color:${s.colour}` }, `■ ${s.name} `)));
  return el("figure", { class: "chart" }, el("figcaption", {}, `${title} (${unit})`), svg, legend);
}

export function statsSeries(samples: Sample[]): { rtf: Series[]; bandwidth: Series[]; latency: Series[] } {
  const robots = [...new Set(samples.flatMap((s) => Object.keys(s.robots ?? {})))].sort();
  const at = (s: Sample): number => s.sim_time_ms / 1000; // match time, as the replay's clock
  const rtf = [{ name: "real-time factor", colour: "#2e7d32", points: samples.map((s) => [at(s), s.real_time_factor] as [number, number]) }];
  const bandwidth: Series[] = [];
  const latency: Series[] = [];
  robots.forEach((robot) => {
    const colour = colourOf(robot);
    const kb: [number, number][] = [];
    const rtt: [number, number][] = [];
    for (let i = 1; i < samples.length; i++) {
      const a = samples[i - 1].robots?.[robot];
      const b = samples[i].robots?.[robot];
      const dt = samples[i].real_time_s - samples[i - 1].real_time_s;
      if (a && b && dt > 0) kb.push([at(samples[i]), (b.bytes_in + b.bytes_out - a.bytes_in - a.bytes_out) / 1000 / dt]);
      if (b && b.round_trip_ms !== null) rtt.push([at(samples[i]), b.round_trip_ms]);
    }
    bandwidth.push({ name: robot, colour, points: kb });
    latency.push({ name: robot, colour, points: rtt });
  });
  return { rtf, bandwidth, latency };
}

/** Draws the charts; returns the function that moves their playheads to a match time (ms). */
export async function drawStats(root: HTMLElement, url: string): Promise<(ms: number) => void> {
  const samples = await getJson<Sample[]>(url);
  if (samples.length === 0) return () => undefined;
  const { rtf, bandwidth, latency } = statsSeries(samples);
  const xmax = Math.max(1, ...samples.map((s) => s.sim_time_ms / 1000));
  root.append(
    lineChart("Real-time factor", "sim s per wall s", rtf, "plot-rtf", xmax),
    lineChart("Robot API bandwidth", "kB/s, both directions", bandwidth, "plot-bandwidth", xmax),
    lineChart("Robot API round trip", "ms", latency, "plot-latency", xmax),
  );
  const heads = Array.from(root.querySelectorAll<SVGLineElement>("line.playhead"));
  let shown = "";
  return (ms: number) => {
    const x = (PAD + Math.min(1, ms / 1000 / xmax) * (WIDTH - PAD - 8)).toFixed(1);
    if (x === shown) return; // unchanged: no write, no layout
    shown = x;
    for (const head of heads) { head.setAttribute("x1", x); head.setAttribute("x2", x); }
  };
}
