// SPDX-License-Identifier: MIT
// The report's view, shared by the report page of `llsfsim report --html` (report.ts) and the
// viewer's batch page (viewer.ts): given the batch's data (to_json in study/src/report.cpp) it
// draws, like the thesis' Figures 6.3 and 6.5, box plots of the points per configuration (one
// box per variant, a dot per run) and per phase, then the tables: points per variant, the
// differences against the baseline with their bootstrap 95 % intervals, and every statistic's
// mean.
import * as Plot from "@observablehq/plot";

// The data, as written by llsf::sim::to_json (format_version 2). Non-finite numbers are null.
interface Summary {
  n: number;
  mean: number | null;
  median: number | null;
  q1: number | null;
  q3: number | null;
  min: number | null;
  max: number | null;
}

interface VariantData {
  variant: string;
  runs: number;
  passed: number;
  pass_rate: number | null;
  statistics: Record<string, Summary>;
}

interface DifferenceData {
  variant: string;
  baseline: string;
  statistic: string;
  diff: number | null;
  ci_low: number | null;
  ci_high: number | null;
  method: string;
  pairs: number;
  n_variant: number;
  n_baseline: number;
  comparisons: number;
  enough_games: boolean;
  separated: boolean;
  games_needed: number | null;
}

interface RunData {
  variant: string;
  seed: number;
  passed: boolean;
  result_hash: string;
  statistics: Record<string, number | null>;
}

export interface ReportData {
  format: string;
  format_version: number;
  llsfsim_version: string;
  batch: {
    id: number;
    kind: string;
    scenario_name: string;
    scenario_file: string;
    scenario_hash: string;
    runs_per_variant: number;
    variants: number;
    seeds: string;
  };
  variants: VariantData[];
  differences: DifferenceData[];
  runs: RunData[];
}

/// The statistics whose differences are listed in the differences table, in this order.
const kDifferenceStatistics = ["points", "exploration_points", "production_points", "deliveries"];
const kPhaseColors = {exploration: "#e3a33b", production: "#4c78a8"};

// ---------------------------------------------------------------------------------------------
// Small DOM helpers.

export type Child = Node | string | number;

export function el<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Record<string, string> = {},
  ...children: Child[]
): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  for (const c of children) e.append(typeof c === "number" ? String(c) : c);
  return e;
}

function fixed(v: number | null | undefined, digits = 1): string {
  return v === null || v === undefined ? "–" : v.toFixed(digits);
}

function signed(v: number | null | undefined): string {
  if (v === null || v === undefined) return "–";
  return (v > 0 ? "+" : v < 0 ? "−" : "±") + Math.abs(v).toFixed(1);
}

export function table(head: string[], rows: Child[][], attrs: Record<string, string> = {}): HTMLElement {
  return el(
    "table",
    attrs,
    el("thead", {}, el("tr", {}, ...head.map((h) => el("th", {}, h)))),
    el("tbody", {}, ...rows.map((r) => el("tr", {}, ...r.map((c) => el("td", {}, c))))),
  );
}

// ---------------------------------------------------------------------------------------------
// Variant names: `config=P3-P3` is shown as `P3-P3` under the axis label `config` when every
// variant has one matrix axis and it is the same one.

interface Naming {
  label: (variant: string) => string;
  axis: string;
}

function naming(variants: string[]): Naming {
  const keys = new Set(variants.map((v) => (/^[^=,]+=[^,]*$/.test(v) ? v.split("=")[0] : "")));
  if (keys.size === 1 && !keys.has("")) {
    const [axis] = keys;
    return {label: (v) => v.slice(axis.length + 1), axis: axis};
  }
  return {label: (v) => (v === "" ? "(no matrix)" : v), axis: "variant"};
}

/// A horizontal offset in [-1, 1) for a run's dot, from its variant and seed: the same page
/// every time (no Math.random), runs of one variant spread over the box's width.
function jitter(variant: string, seed: number): number {
  let h = 0x811c9dc5;  // FNV-1a, then MurmurHash3's finalizer to spread the last characters
  for (const c of `${variant}/${seed}`) {
    h ^= c.charCodeAt(0);
    h = Math.imul(h, 0x01000193);
  }
  h ^= h >>> 16;
  h = Math.imul(h, 0x85ebca6b);
  h ^= h >>> 13;
  h = Math.imul(h, 0xc2b2ae35);
  h ^= h >>> 16;
  return ((h >>> 0) / 0x100000000) * 2 - 1;
}

// ---------------------------------------------------------------------------------------------
// The plots. Each plot's svg carries data-plot="NAME" (the tests count its boxes).

function mark(plot: SVGSVGElement | HTMLElement, name: string): HTMLElement | SVGSVGElement {
  const svg = plot instanceof SVGSVGElement ? plot : plot.querySelector(":scope > svg");
  svg?.setAttribute("data-plot", name);
  plot.classList.add("llsf-plot");
  return plot;
}

function pointsPlot(data: ReportData, names: Naming, width: number): Node {
  const rows = data.runs.map((r) => ({
    variant: names.label(r.variant),
    seed: r.seed,
    passed: r.passed,
    points: r.statistics["points"] ?? null,
    jitter: jitter(r.variant, r.seed) * 0.55,
  }));
  const domain = data.variants.map((v) => names.label(v.variant));
  const marginLeft = 50;
  const facetWidth = (width - marginLeft - 20) / Math.max(1, domain.length);
  const inset = Math.max(4, facetWidth * 0.2);
  const longest = Math.max(...domain.map((d) => d.length));
  const rotate = longest * 7 > facetWidth * 0.9;
  // Every run with the same points: a scale of zero extent draws nothing readable; give it room.
  const values = rows.map((r) => r.points).filter((p): p is number => p !== null);
  const lo = Math.min(...values);
  const hi = Math.max(...values);
  const flat = values.length > 0 && hi - lo < 1;
  return mark(
    Plot.plot({
      width,
      height: 380,
      style: {fontSize: "12px"},
      marginLeft,
      marginRight: 20,
      marginBottom: rotate ? 90 : 45,
      fx: {
        domain,
        label: names.axis,
        axis: "bottom",
        labelAnchor: "center",
        padding: 0.08,
        tickRotate: rotate ? -25 : 0,
      },
      x: {axis: null, domain: [-1, 1]},
      y: flat
        ? {label: "points", grid: true, nice: true, domain: [lo - 10, hi + 10]}
        : {label: "points", grid: true, nice: true},
      marks: [
        Plot.frame({stroke: "#ddd", anchor: "bottom"}),
        Plot.boxY(rows, {
          fx: "variant",
          y: "points",
          fill: "#c6d4e6",
          insetLeft: inset,
          insetRight: inset,
        }),
        Plot.dot(rows, {
          fx: "variant",
          x: "jitter",
          y: "points",
          r: 3.5,
          fill: (d) => (d.passed ? "#2b5d9a" : "#c0392b"),
          fillOpacity: 0.75,
          stroke: "white",
          strokeWidth: 0.5,
          title: (d) => `seed ${d.seed}: ${d.points} points${d.passed ? "" : " (a test failed)"}`,
        }),
      ],
    }),
    "points",
  );
}

function phasesPlot(data: ReportData, names: Naming, width: number): Node {
  const rows = data.runs.flatMap((r) => [
    {
      variant: names.label(r.variant),
      seed: r.seed,
      phase: "exploration",
      points: r.statistics["exploration_points"] ?? null,
    },
    {
      variant: names.label(r.variant),
      seed: r.seed,
      phase: "production",
      points: r.statistics["production_points"] ?? null,
    },
  ]);
  const domain = data.variants.map((v) => names.label(v.variant));
  const facetWidth = (width - 70) / Math.max(1, domain.length);
  const longest = Math.max(...domain.map((d) => d.length));
  const rotate = longest * 7 > facetWidth * 0.9;
  return mark(
    Plot.plot({
      width,
      height: 380,
      style: {fontSize: "12px"},
      marginLeft: 50,
      marginRight: 20,
      marginTop: rotate ? 70 : 30,
      fx: {
        domain,
        label: null,
        axis: "top",
        labelAnchor: "center",
        padding: 0.1,
        tickRotate: rotate ? -25 : 0,
      },
      x: {domain: ["exploration", "production"], axis: null},
      y: {label: "points", grid: true, nice: true, zero: true},
      color: {
        domain: ["exploration", "production"],
        range: [kPhaseColors.exploration, kPhaseColors.production],
        legend: true,
      },
      marks: [
        Plot.frame({stroke: "#ddd", anchor: "bottom"}),
        Plot.boxY(rows, {fx: "variant", x: "phase", y: "points", fill: "phase", r: 0}),
        // The runs on the boxes' centre lines: a phase whose runs all scored the same (a flat
        // box) still shows its colour.
        Plot.dot(rows, {
          fx: "variant",
          x: "phase",
          y: "points",
          r: 3,
          fill: "phase",
          stroke: "white",
          strokeWidth: 0.5,
          title: (d) => `seed ${d.seed}: ${d.points} ${d.phase} points`,
        }),
      ],
    }),
    "phases",
  );
}

// ---------------------------------------------------------------------------------------------
// The tables.

function pointsTable(data: ReportData, names: Naming): HTMLElement {
  const rows = data.variants.map((v) => {
    const p = v.statistics["points"];
    const rate = v.pass_rate === null ? "–" : `${Math.round(v.pass_rate * 100)} %`;
    return [
      names.label(v.variant),
      v.runs,
      `${v.passed}/${v.runs} (${rate})`,
      fixed(p?.mean),
      fixed(p?.median),
      fixed(p?.q1),
      fixed(p?.q3),
      fixed(p?.min, 0),
      fixed(p?.max, 0),
    ];
  });
  return table(
    [names.axis, "runs", "passed", "mean", "median", "q1", "q3", "min", "max"],
    rows,
    {"data-table": "variants"},
  );
}

function differencesTable(data: ReportData, names: Naming): HTMLElement {
  if (data.differences.length === 0) {
    return el("p", {class: "note"}, "One variant only: no differences.");
  }
  const rows: Child[][] = [];
  for (const statistic of kDifferenceStatistics) {
    for (const d of data.differences.filter((x) => x.statistic === statistic)) {
      // The star is the report's verdict: enough games, separated after Holm's correction.
      const significant = d.separated;
      const cell = el(
        "span",
        significant ? {class: "significant"} : {},
        `[${signed(d.ci_low)}, ${signed(d.ci_high)}]${significant ? " *" : ""}`,
      );
      const games =
        d.method === "paired by seed" ? `${d.pairs} pairs` : `${d.n_variant} vs ${d.n_baseline}`;
      const note = d.enough_games
        ? ""
        : "too few games" + (d.games_needed !== null ? `; about ${d.games_needed} needed` : "");
      rows.push([names.label(d.variant), statistic, signed(d.diff), cell, games, note]);
    }
  }
  const baseline = names.label(data.differences[0].baseline);
  return el(
    "div",
    {},
    el(
      "p",
      {class: "note"},
      `Mean of the variant minus the mean of ${baseline} (the first variant), paired by seed ` +
        "where both played the same seeds, with an expanded percentile-bootstrap 95 % interval " +
        "(2,000 resamples); * marks differences separated at 5 % after Holm's correction over " +
        "the variants, with at least 10 games (pairs) each.",
    ),
    table([names.axis, "statistic", "difference", "95 % interval", "games", "note"], rows, {
      "data-table": "differences",
    }),
  );
}

function statisticsTable(data: ReportData, names: Naming): HTMLElement {
  const statistics = [...new Set(data.variants.flatMap((v) => Object.keys(v.statistics)))].sort();
  const rows = statistics.map((s) => [
    s,
    ...data.variants.map((v) => {
      const x = v.statistics[s];
      return x ? `${fixed(x.mean, 2)} (${fixed(x.median, 1)})` : "–";
    }),
  ]);
  return el(
    "details",
    {},
    el("summary", {}, "Every statistic: mean (median) per variant"),
    table(["statistic", ...data.variants.map((v) => names.label(v.variant))], rows, {
      "data-table": "statistics",
    }),
  );
}

// ---------------------------------------------------------------------------------------------
// The page.

export function renderReport(root: HTMLElement, data: ReportData): void {
  const names = naming(data.variants.map((v) => v.variant));
  const width = Math.max(480, Math.min(960, root.clientWidth || 960));
  const b = data.batch;
  const runs = data.runs.length;
  root.replaceChildren(
    el("h1", {}, `Points per configuration: ${b.scenario_name}`),
    el(
      "p",
      {class: "meta"},
      `${b.scenario_file} · batch ${b.id} · ${data.variants.length} variant(s), ${runs} run(s)` +
        ` · seeds ${b.seeds || "–"} · scenario ${b.scenario_hash} · llsfsim ${data.llsfsim_version}`,
    ),
    el("h2", {}, "Total points per variant"),
    el(
      "p",
      {class: "note"},
      "Box: quartiles and median; whiskers: the data within 1.5 × the interquartile range; " +
        "dots: the runs (blue passed its test cases, red failed one), spread sideways to be seen.",
    ),
    pointsPlot(data, names, width),
    el("h2", {}, "Points per phase"),
    el("p", {class: "note"}, "Exploration and production points of each run, per variant."),
    phasesPlot(data, names, width),
    el("h2", {}, "Points per variant"),
    pointsTable(data, names),
    el("h2", {}, "Differences"),
    differencesTable(data, names),
    statisticsTable(data, names),
  );
}
