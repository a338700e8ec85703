// SPDX-License-Identifier: MIT
// `llsfsim batch --slurm` where sbatch cannot submit (here: not on the PATH): exit 2, and
// nothing is left behind -- no empty batch row, no job script (docs/cluster.md).
#include <doctest/doctest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"
#include "llsf/study/cluster.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

/// PATH set to `dir` for the object's lifetime.
struct PathOnly {
  explicit PathOnly(const std::string& dir) : old_(::getenv("PATH") ? ::getenv("PATH") : "") {
    ::setenv("PATH", dir.c_str(), 1);
  }
  ~PathOnly() { ::setenv("PATH", old_.c_str(), 1); }
  PathOnly(const PathOnly&) = delete;
  PathOnly& operator=(const PathOnly&) = delete;

 private:
  std::string old_;
};

}  // namespace

TEST_CASE("batch --slurm without sbatch: exit 2, no batch row and no job script left") {
  const llsf::test::TempDir dir("llsf_app_slurm_fail");
  dir.write("tiny.yaml", "name: tiny\nduration_s: 5\nrobots: {count: 1}\n");
  std::filesystem::create_directories(dir.file("empty-bin"));
  const std::string db = dir.file("s.db");
  // A batch that exists already stays (it may hold runs of an earlier local batch).
  REQUIRE(llsfsim({"batch", dir.file("tiny.yaml"), "--runs", "1", "--db", db, "--no-record", "-q"})
              .code == 0);
  Run r;
  {
    const PathOnly path(dir.file("empty-bin"));
    r = llsfsim({"batch", dir.file("tiny.yaml"), "--runs", "3", "--db", db, "--slurm"});
  }
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "(sbatch not found: is slurm-client installed?)"));
  CHECK(has(r.err, "nothing was submitted: the job script and the new batch rows are removed"));
  const llsf::study::StatsStore store(db);
  REQUIRE(store.batches().size() == 1);  // the earlier one only
  CHECK(store.batches().front().runs_per_variant == 1);
  CHECK_FALSE(std::filesystem::exists(llsf::study::slurm_dir(db)));
}
