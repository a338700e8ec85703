// SPDX-License-Identifier: MIT
// `llsfsim report`: statistics of a stored batch per variant, differences between variants,
// CSV export, an HTML page with box plots.
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

namespace {

struct ReportOptions {
  std::optional<std::int64_t> batch;
  std::string db{study::StatsStore::kDefaultPath};
  std::string csv;
  std::string html;
  bool list = false;
};

int report(const ReportOptions& o, std::ostream& out, std::ostream& err) {
  try {
    const study::StatsStore store(o.db);
    const std::vector<study::StoredBatch> batches = store.batches();
    if (o.list) {
      for (const study::StoredBatch& b : batches) {
        out << b.id << "  " << b.kind << "  " << b.scenario_name << "  " << b.scenario_file << "  ";
        if (b.kind == "run") {
          // The single games of `llsfsim run`: a collection with no planned size, never
          // "finished" (docs/statistics.md), so neither finished nor unfinished.
          out << b.variants << " variant(s), " << store.run_keys(b.id).size()
              << " game(s) of llsfsim run\n";
          continue;
        }
        out << b.variants << " variant(s) x " << b.runs_per_variant << " run(s)  "
            << (b.finished.empty() ? "unfinished" : "finished " + b.finished) << "\n";
      }
      return kExitOk;
    }
    std::optional<std::int64_t> id = o.batch;
    if (!id) {
      // The latest batch (of `llsfsim batch`, else any).
      for (const study::StoredBatch& b : batches) {
        if (b.kind == "batch") id = b.id;
      }
      if (!id && !batches.empty()) id = batches.back().id;
    }
    if (!id) {
      err << "llsfsim report: " << store.path() << " holds no batch (run llsfsim batch first)\n";
      return kExitBadInput;
    }
    const study::BatchReport r = study::make_report(store, *id);
    out << study::to_text(r);
    if (!o.csv.empty()) {
      std::ofstream f(o.csv);
      f << study::to_csv(r);
      if (!f) {
        err << "llsfsim report: cannot write " << o.csv << "\n";
        return kExitBadInput;
      }
    }
    if (!o.html.empty()) {
      const std::string page =
          study::to_html(r, study::to_json(r, study::run_values(store, *id)), study::viewer_dir());
      // Written next to its place and renamed: a failed write leaves no half page behind.
      const std::string tmp = o.html + ".tmp";
      std::ofstream f(tmp, std::ios::binary);
      f << page;
      f.close();
      if (!f || std::rename(tmp.c_str(), o.html.c_str()) != 0) {
        std::remove(tmp.c_str());
        err << "llsfsim report: cannot write " << o.html << "\n";
        return kExitBadInput;
      }
    }
  } catch (const study::ViewerBundleMissing& e) {
    err << "llsfsim report: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const study::StatsError& e) {
    err << "llsfsim report: " << e.what() << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

Action add_report_command(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  app.add_option("batch", o->batch, "Batch id (default: the latest batch; see --list)");
  app.add_option("--db", o->db,
                 "Statistics store: a SQLite file or a postgresql://USER@HOST:PORT/DB URL "
                 "(docs/statistics.md)")
      ->capture_default_str();
  app.add_option("--csv", o->csv,
                 "Also write every statistic per variant (n, mean, median, quartiles, min, max, "
                 "pass rate, runs: n of runs) as CSV");
  app.add_option("--html", o->html,
                 "Also write a self-contained HTML page: box plots of the points per variant and "
                 "per phase, the tables, and every run's statistics as JSON");
  app.add_flag("--list", o->list, "List the stored batches");
  app.footer(
      "Per variant: runs, pass rate and the distribution of the points; then every variant's "
      "mean points against the first variant's, paired by seed where both played the same "
      "seeds, with a bootstrap 95 % interval (* = separated at 5 % after Holm's correction over "
      "the variants; no star and no verdict below 10 games, but how many would be needed; "
      "docs/statistics.md). The HTML page inlines the viewer's bundle from $LLSF_VIEWER_DIR or "
      "viewer/dist of the data directory (`make viewer` builds it).\n"
      "Exit code: 0 done, 2 bad input (a bad store or batch, a database server that cannot be "
      "reached, a file that cannot be written, a missing viewer bundle), 3 internal error (a bug: "
      "please report it).");
  return [o](std::ostream& out, std::ostream& err) { return report(*o, out, err); };
}

}  // namespace llsf::app
