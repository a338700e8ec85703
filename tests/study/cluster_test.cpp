// SPDX-License-Identifier: MIT
// Batches beyond the scenario's seed list (--runs, --seeds) and the Slurm pieces without a
// cluster: array specs, job scripts, squeue/sacct lines, the job file. The real cluster:
// tests/app/cluster_test.sh (CTest cluster_batch).
#include "llsf/study/cluster.h"

#include <doctest/doctest.h>

#include <fstream>
#include <string>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

using llsf::core::ConfigError;
using llsf::study::Scenario;
using llsf::study::SeedChoice;
using Seeds = std::vector<std::uint64_t>;

TEST_CASE("--seeds: lists and ranges, bounded, each seed once") {
  using llsf::study::parse_seed_list;
  CHECK(parse_seed_list("7") == Seeds{7});
  CHECK(parse_seed_list("1,5,9-12") == Seeds{1, 5, 9, 10, 11, 12});
  CHECK(parse_seed_list("0-2") == Seeds{0, 1, 2});
  CHECK(parse_seed_list("9223372036854775807") == Seeds{9223372036854775807ULL});
  CHECK_THROWS_WITH_AS(parse_seed_list("1,,2"), doctest::Contains("is empty"), ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("1,a"), doctest::Contains("'a' is not a seed"), ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("-3"), doctest::Contains("'-3' is negative"), ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("5-3"), doctest::Contains("empty range"), ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("1-3,2"), doctest::Contains("seed 2 is given twice"),
                       ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("9223372036854775808"), doctest::Contains("too large"),
                       ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("1-100001"), doctest::Contains("more than 100000"),
                       ConfigError);
  CHECK_THROWS_WITH_AS(parse_seed_list("0-18446744073709551"), doctest::Contains("more than"),
                       ConfigError);
}

TEST_CASE("--runs beyond the scenario's list: the seeds after its largest, counting up") {
  Scenario s;
  s.seeds = {7, 3};
  CHECK(batch_seeds(s, SeedChoice{1, {}}) == Seeds{7});
  CHECK(batch_seeds(s, SeedChoice{2, {}}) == Seeds{7, 3});
  CHECK(batch_seeds(s, SeedChoice{5, {}}) == Seeds{7, 3, 8, 9, 10});
  s.seeds = {4};
  CHECK(batch_seeds(s, SeedChoice{3, {}}) == Seeds{4, 5, 6});
  CHECK(batch_seeds(s, SeedChoice{{}, {9, 2}}) == Seeds{9, 2});
  CHECK_THROWS_AS(batch_seeds(s, SeedChoice{2, {1}}), ConfigError);
  CHECK_THROWS_AS(batch_seeds(s, SeedChoice{0, {}}), ConfigError);
  CHECK_THROWS_WITH_AS(batch_seeds(s, SeedChoice{100001, {}}),
                       doctest::Contains("at most 100000 seeds per variant"), ConfigError);
}

TEST_CASE("batch identity: --seeds equal to --runs N's seeds is that batch; others are not") {
  llsf::study::ScenarioFile f;
  f.file = "x.yaml";
  Scenario a;
  a.name = "x";
  a.variant = "a";
  a.seeds = {3, 4};
  Scenario b = a;
  b.variant = "b";
  f.variants = {a, b};
  const auto runs3 = llsf::study::batch_key(f, "h", SeedChoice{3, {}});
  CHECK(runs3.scenario_hash == "h");
  CHECK(runs3.runs_per_variant == 3);
  CHECK(runs3.seeds == Seeds{3, 4, 5});
  const auto same = llsf::study::batch_key(f, "h", SeedChoice{{}, {3, 4, 5}});
  CHECK(same.scenario_hash == "h");
  CHECK(same.runs_per_variant == 3);
  const auto other = llsf::study::batch_key(f, "h", SeedChoice{{}, {3, 4, 6}});
  CHECK(other.scenario_hash.starts_with("h+seeds-"));
  CHECK(other.scenario_hash.size() == std::string("h+seeds-").size() + 16);
  CHECK(llsf::study::batch_key(f, "h", SeedChoice{{}, {6, 4, 3}}).scenario_hash !=
        other.scenario_hash);
  // Seed-major pairs: every variant's first seed, then the second.
  const auto pairs = llsf::study::batch_pairs(f, SeedChoice{2, {}});
  REQUIRE(pairs.size() == 4);
  CHECK(pairs[0].variant == 0);
  CHECK(pairs[1].variant == 1);
  CHECK(pairs[1].seed == 3);
  CHECK(pairs[2].seed == 4);
}

TEST_CASE("Slurm: array specs, the job script, squeue and sacct lines") {
  using llsf::study::array_spec;
  CHECK(array_spec({0, 1, 2, 3}, 0) == "0-3");
  CHECK(array_spec({7, 0, 1, 3, 9, 10, 1}, 2) == "0-1,3,7,9-10%2");
  llsf::study::SlurmScript s;
  s.tasks = {0, 1, 4};
  s.partition = "short";
  s.time_limit = "10:00";
  s.array_throttle = 4;
  s.cpus_per_task = 2;
  s.sbatch_args = {"--mem=1G", "--qos=low"};
  s.log_dir = "/shared/x-slurm";
  s.workdir = "/shared";
  s.command = {"/opt/llsfsim", "batch", "/shared/a b.yaml", "--db", "/shared/x.db"};
  const std::string text = llsf::study::slurm_script(s);
  CHECK(text.starts_with("#!/bin/bash\n"));
  CHECK(text.find("#SBATCH --array=0-1,4%4\n") != std::string::npos);
  CHECK(text.find("#SBATCH --partition=short\n") != std::string::npos);
  CHECK(text.find("#SBATCH --time=10:00\n") != std::string::npos);
  CHECK(text.find("#SBATCH --cpus-per-task=2\n") != std::string::npos);
  CHECK(text.find("#SBATCH --requeue\n") != std::string::npos);
  CHECK(text.find("#SBATCH --mem=1G\n#SBATCH --qos=low\n") != std::string::npos);
  CHECK(text.find("#SBATCH --chdir=/shared\n#SBATCH --output=/shared/x-slurm/slurm-%A_%a.out\n") !=
        std::string::npos);
  CHECK(text.find("exec /opt/llsfsim batch '/shared/a b.yaml' --db /shared/x.db --task "
                  "\"$SLURM_ARRAY_TASK_ID\"\n") != std::string::npos);
  s.sbatch_args = {"--mem=1G\nrm -rf /"};
  CHECK_THROWS_WITH_AS(llsf::study::slurm_script(s), doctest::Contains("line break"), ConfigError);
  s.tasks.clear();
  CHECK_THROWS_AS(llsf::study::slurm_script(s), ConfigError);
  CHECK(llsf::study::shell_quote("it's") == "'it'\\''s'");

  const auto tasks = llsf::study::parse_slurm_tasks(
      "12_3|RUNNING|None\n12_[4-6,9%2]|PENDING|JobArrayTaskLimit\n13|RUNNING|None\n"
      "12_2|CANCELLED by 0|0:15\n12_2.batch|CANCELLED|0:15\ngarbage\n12_x|RUNNING|\n");
  REQUIRE(tasks.size() == 3);
  CHECK(tasks[0].job_id == "12");
  CHECK(tasks[0].task == 3);
  CHECK(tasks[0].state == "RUNNING");
  CHECK(tasks[1].task == -1);
  CHECK(tasks[1].pending == std::vector<int>{4, 5, 6, 9});
  CHECK(tasks[2].state == "CANCELLED");
  CHECK(tasks[2].detail == "0:15");
}

TEST_CASE("Slurm: shard names, the job file") {
  const llsf::test::TempDir dir;
  const std::string db = dir.file("study.db");
  CHECK(llsf::study::shard_path(db, 3) == dir.file("study.shard-00003.db"));
  CHECK(llsf::study::existing_shards(db).empty());
  std::ofstream(llsf::study::shard_path(db, 12)) << "";
  std::ofstream(llsf::study::shard_path(db, 2)) << "";
  std::ofstream(dir.file("study.shard-x.db")) << "";
  CHECK(
      llsf::study::existing_shards(db) ==
      std::vector<std::string>{dir.file("study.shard-00002.db"), dir.file("study.shard-00012.db")});
  CHECK(llsf::study::read_jobs(db).empty());
  llsf::study::SlurmJob j;
  j.job_id = "42";
  j.submitted = "2026-11-26T10:00:00Z";
  j.games_per_task = 6;
  j.array = "0-6";
  j.stored_at_submit = 3;
  j.total = 40;
  j.scenarios = {"/a.yaml", "/b.yaml"};
  llsf::study::append_job(db, j);
  llsf::study::append_job(db, j);
  const auto jobs = llsf::study::read_jobs(db);
  REQUIRE(jobs.size() == 2);
  CHECK(jobs[1].job_id == "42");
  CHECK(jobs[1].games_per_task == 6);
  CHECK(jobs[1].total == 40);
  CHECK(jobs[1].scenarios == std::vector<std::string>{"/a.yaml", "/b.yaml"});
  CHECK(jobs[1].batch.empty());
  // The batch's identity and the script: optional fields before the scenarios.
  j.batch = "0123456789abcdef:20";
  j.script = "/s/job-2.sh";
  llsf::study::append_job(db, j);
  const auto three = llsf::study::read_jobs(db);
  REQUIRE(three.size() == 3);
  CHECK(three[2].batch == "0123456789abcdef:20");
  CHECK(three[2].script == "/s/job-2.sh");
  CHECK(three[2].scenarios == std::vector<std::string>{"/a.yaml", "/b.yaml"});
  std::ofstream(llsf::study::job_file_path(db), std::ios::app) << "43\tx\n";
  CHECK_THROWS_WITH_AS(llsf::study::read_jobs(db),
                       doctest::Contains("slurm-jobs:4: not a job line"), ConfigError);
  CHECK(llsf::study::is_database_url("postgresql://u@h:5432/db"));
  CHECK(llsf::study::job_file_path("postgresql://u:pw@h:5432/db?sslmode=require")
            .ends_with("/llsfsim-slurm/h_5432_db.slurm-jobs"));
  CHECK(!llsf::study::is_database_url("study.db"));
}

}  // namespace
