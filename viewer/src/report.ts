// SPDX-License-Identifier: MIT
// The report page of `llsfsim report --html`: reads the batch's data (to_json in
// study/src/report.cpp) from <script id="llsf-report-data" type="application/json"> and draws it
// with report_view.ts: box plots of the points per configuration (one box per variant, a dot per
// run) and per phase, then the tables.
import {el, renderReport, type ReportData} from "./report_view";

function main(): void {
  const root = document.getElementById("llsf-report");
  if (!root) return;
  const script = document.getElementById("llsf-report-data");
  try {
    if (!script?.textContent) throw new Error("the page holds no report data");
    const data = JSON.parse(script.textContent) as ReportData;
    if (data.format !== "llsfsim-report") throw new Error(`unknown data format ${data.format}`);
    renderReport(root, data);
    root.setAttribute("data-ready", "true");
  } catch (e) {
    root.replaceChildren(el("p", {class: "error"}, `llsfsim report: ${String(e)}`));
    root.setAttribute("data-error", String(e));
  }
}

main();
