// --quality draft|default|final (bake/ddgi/quality.h): the default level bakes the same bytes as no
// --quality; each level sets its documented spacing rule, probe budget and rays, says so in the
// summary, and costs what it promises (draft fewer rays than the default, final more); options given
// explicitly win over the level and are named; a mistyped level gets one line with the nearest.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "bake/ddgi/quality.h"
#include "tests/support/cli_errors.h"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");
// The checks after the bake read the file, not the level: off, so that only the bake is timed.
const std::string kQuick = " --ddgi --progress json --reconstruction-check off --leak-audit off";

struct Baked {
  CliResult run;
  nlohmann::json summary;
};

Baked bake(const std::string& out, const std::string& options) {
  Baked b;
  b.run = run_gibake_cli(kSample + kQuick + " --out " + shell_quote(out) + " " + options);
  for (const std::string& line : split_lines(b.run.err)) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("event", "") == "summary") b.summary = j;
  }
  return b;
}

uint64_t total_rays(const nlohmann::json& summary) {
  uint64_t total = 0;
  for (const auto& [kind, n] : summary["rays"].items()) total += n.get<uint64_t>();
  return total;
}

class Quality : public ::testing::Test {
 protected:
  std::string file(const std::string& name) const { return scratch_.path(name); }
  ScratchDir scratch_{"quality"};
};

TEST_F(Quality, DefaultLevelBakesTheSameBytesAsNoLevel) {
  const Baked none = bake(file("none.gibake"), "");
  const Baked level = bake(file("default.gibake"), "--quality default");
  ASSERT_EQ(none.run.exit_code, 0) << none.run.err;
  ASSERT_EQ(level.run.exit_code, 0) << level.run.err;
  const std::string a = read_text_file(file("none.gibake")), b = read_text_file(file("default.gibake"));
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "--quality default changed the file";
  EXPECT_EQ(level.summary.value("quality", ""),
            "quality default: spacing 0.25 m (longest side / 24 within 0.25-1 m, at least 8 cells across, at most "
            "32768 probes), rays "
            "512-4096, ray budget 1024, bounces until roulette ends them, refined volumes within 8192 probes at a "
            "ray budget of 1024, probe filter off, surface fit on (262144 points found by 64 rays a probe, 144 paths "
            "each, roulette from hit 1, also ended in the probes fitted to the whole paths, residuals relative to the "
            "fitted light to the power 0.5)");
  EXPECT_EQ(none.summary.value("quality", ""), level.summary.value("quality", ""));
  // The level leaves the probe filter off (its atlases are fitted), as the file records it.
  const CliResult info = run_gibake_cli("info " + shell_quote(file("none.gibake")) + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json settings = nlohmann::json::parse(info.out)["metadata"]["settings"];
  EXPECT_FALSE(settings.contains("probe_filter")) << settings.dump();
  // Its fit's paths run whole and are also ended in the probes' light (--fit-gather both), as the
  // file records.
  EXPECT_EQ(settings["surface_fit"].value("gather", ""), "both") << settings.dump();
  EXPECT_EQ(settings["surface_fit"].value("passes", 0), 2) << settings.dump();
}

// --fit-passes 1 ends the fit's paths in the baked probes and fits once: another file, and the
// summary and the file say so.
TEST_F(Quality, FitPassesOneEndsThePathsInTheBakedProbes) {
  const Baked none = bake(file("none.gibake"), "");
  const Baked one = bake(file("one.gibake"), "--fit-passes 1");
  for (const Baked* b : {&none, &one}) ASSERT_EQ(b->run.exit_code, 0) << b->run.err;
  EXPECT_FALSE(read_text_file(file("none.gibake")) == read_text_file(file("one.gibake")));
  const std::string q = one.summary.value("quality", "");
  EXPECT_NE(q.find("also ended in the probes' light"), std::string::npos) << q;
  const CliResult info = run_gibake_cli("info " + shell_quote(file("one.gibake")) + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json settings = nlohmann::json::parse(info.out)["metadata"]["settings"];
  EXPECT_EQ(settings["surface_fit"].value("passes", 0), 1) << settings.dump();
}

// --fit-solves overrides the level's: 2 is the default level's own (the same bytes), 1 solves once
// (another file), and the summary says which and that it was given.
TEST_F(Quality, FitSolvesGivenWinOverTheLevel) {
  const Baked none = bake(file("none.gibake"), "");
  const Baked twice = bake(file("twice.gibake"), "--fit-solves 2");
  const Baked once = bake(file("once.gibake"), "--fit-solves 1");
  for (const Baked* b : {&none, &twice, &once}) ASSERT_EQ(b->run.exit_code, 0) << b->run.err;
  const std::string a = read_text_file(file("none.gibake"));
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == read_text_file(file("twice.gibake"))) << "--fit-solves 2 changed the default's file";
  EXPECT_FALSE(a == read_text_file(file("once.gibake"))) << "--fit-solves 1 left the second solve in";
  const std::string relative = "residuals relative to the fitted light to the power 0.5";
  const std::string q_twice = twice.summary.value("quality", ""), q_once = once.summary.value("quality", "");
  EXPECT_NE(q_twice.find(relative), std::string::npos) << q_twice;
  EXPECT_EQ(q_once.find(relative), std::string::npos) << q_once;
  for (const std::string& q : {q_twice, q_once})
    EXPECT_NE(q.find("given explicitly: --fit-solves"), std::string::npos) << q;
}

TEST_F(Quality, EachLevelSetsItsValuesAndCostsWhatItPromises) {
  const Baked draft = bake(file("draft.gibake"), "--quality draft");
  const Baked normal = bake(file("default.gibake"), "");
  // Final's refinement would place about 35,000 probes at 6 cm in the 2 m sample: the CPU cost of a
  // GPU level. Its budget is checked in the summary line of a bake that gives a smaller one.
  const Baked final = bake(file("final.gibake"), "--quality final --refine-budget 4096");
  for (const Baked* b : {&draft, &normal, &final}) ASSERT_EQ(b->run.exit_code, 0) << b->run.err;
  // The sample is 2 m across: the rule's small-model bound (longest side / min cells) sets it.
  EXPECT_EQ(draft.summary.value("quality", ""),
            "quality draft: spacing 0.5 m (longest side / 12 within 0.5-2 m, at least 4 cells across, at most 4096 "
            "probes), rays 256-1024, "
            "ray budget 512, bounces until roulette ends them, probe filter on, surface fit off");
  EXPECT_EQ(final.summary.value("quality", ""),
            "quality final: spacing 0.125 m (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most "
            "131072 probes), rays "
            "512-16384, ray budget 6144, bounces until roulette ends them, refined volumes within 4096 probes, probe "
            "filter off, surface fit on (1048576 points found by 64 rays a probe, 384 paths each, roulette from hit "
            "3, also ended in the probes' light), depth tiles "
            "8x8; given explicitly: "
            "--refine-budget");
  EXPECT_EQ(gibake::quality_preset(gibake::Quality::Final).refine_budget, 65536u);
  EXPECT_EQ(gibake::quality_preset(gibake::Quality::Default).refine_budget, 8192u);
  EXPECT_EQ(gibake::quality_preset(gibake::Quality::Draft).refine_budget, 0u);
  const uint64_t p_draft = draft.summary["probes"]["total"], p_normal = normal.summary["probes"]["total"],
                 p_final = final.summary["probes"]["total"];
  EXPECT_LT(p_draft, p_normal);
  EXPECT_GT(p_final, p_normal);
  const uint64_t r_draft = total_rays(draft.summary), r_normal = total_rays(normal.summary),
                 r_final = total_rays(final.summary);
  std::printf("probes %llu / %llu / %llu, rays %llu / %llu / %llu (draft / default / final)\n",
              (unsigned long long)p_draft, (unsigned long long)p_normal, (unsigned long long)p_final,
              (unsigned long long)r_draft, (unsigned long long)r_normal, (unsigned long long)r_final);
  EXPECT_LT(r_draft, r_normal);
  EXPECT_GT(r_final, r_normal);
}

// The refined volumes' ray budget: the default level's own 1024, final's the grid's own
// (the summary names none), and one given explicitly wins, is named, and is what the file's
// volume list says each refined volume was traced with (a first batch of half of it).
TEST_F(Quality, RefinedVolumesTakeTheLevelsRayBudgetOrTheGivenOne) {
  EXPECT_EQ(gibake::quality_preset(gibake::Quality::Default).refine_ray_budget, 1024u);
  EXPECT_EQ(gibake::quality_preset(gibake::Quality::Final).refine_ray_budget, 0u);
  const Baked b = bake(file("refine_rays.gibake"), "--refine-ray-budget 300");
  ASSERT_EQ(b.run.exit_code, 0) << b.run.err;
  const std::string line = b.summary.value("quality", "");
  EXPECT_NE(
      line.find("refined volumes within 8192 probes at a ray budget of 300, probe filter off, surface fit on "
                "(262144 points found by 64 rays a probe, 144 paths each, roulette from hit 1, also ended in the "
                "probes fitted to the whole paths, residuals relative to the fitted light to the power 0.5); given "
                "explicitly: --refine-ray-budget"),
      std::string::npos)
      << line;
  const CliResult info = run_gibake_cli("info " + shell_quote(file("refine_rays.gibake")) + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json volumes = nlohmann::json::parse(info.out)["metadata"]["ddgi_volumes"];
  ASSERT_GE(volumes.size(), 2u) << info.out.substr(0, 2000);
  for (const nlohmann::json& v : volumes) {
    const bool refined = v.value("kind", "") == "refined";
    EXPECT_EQ(v.value("ray_budget", 0), refined ? 300 : 1024) << v.dump();
    EXPECT_EQ(v.value("rays", 0), refined ? 150 : 512) << v.dump();
  }
}

// Ray limits that cannot hold are refused in one line that names both figures, and no file is
// written: a --refine-ray-budget above the grid's (a refined probe takes at most the grid's rays,
// with_ray_budget; with --target-error 0 the grid's --rays is the bound), which was traced at the
// grid's, and a --max-rays or --ray-budget given below one batch of --rays, which every probe takes
// first. --rays given over the level's own budget wins, as every option given over the level does
// (the reference tests bake so).
TEST_F(Quality, RayLimitsThatCannotHoldAreRefused) {
  const std::string out = file("limit_refused.gibake");
  const std::string bake_to = kSample + kQuick + " --out " + shell_quote(out);
  const struct {
    const char* options;
    const char* line;
  } cases[] = {
      {" --refine-ray-budget 3072",
       "gibake: error: --refine-ray-budget: got 3072, over the grid's --ray-budget 1024: a refined probe takes at "
       "most the grid's rays; raise --ray-budget too"},
      {" --target-error 0 --rays 256 --refine-ray-budget 512",
       "gibake: error: --refine-ray-budget: got 512, over the grid's --rays 256: a refined probe takes at most the "
       "grid's rays; raise --rays too"},
      {" --rays 512 --max-rays 256",
       "gibake: error: --max-rays: 256 is under one batch of --rays 512, which every probe takes first; lower --rays "
       "or raise --max-rays"},
      {" --ray-budget 300",
       "gibake: error: --ray-budget: 300 is under one batch of --rays 512, which every probe takes first; lower "
       "--rays (to half the budget, so that adaptive rays place the rest)"},
  };
  for (const auto& c : cases) EXPECT_EQ(usage_error_line(bake_to + c.options), c.line);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(Quality, ExplicitOptionsWinOverTheLevelAndAreNamed) {
  const Baked b = bake(file("draft_rays.gibake"), "--quality draft --rays 300 --probe-budget 20 --probe-filter off");
  ASSERT_EQ(b.run.exit_code, 0) << b.run.err;
  const std::string line = b.summary.value("quality", "");
  EXPECT_NE(line.find("rays 300-1024, ray budget 512"), std::string::npos) << line;
  EXPECT_NE(line.find("at most 20 probes"), std::string::npos) << line;
  EXPECT_NE(line.find(", probe filter off, surface fit off; given explicitly: --probe-budget, --rays, --probe-filter"),
            std::string::npos)
      << line;
  EXPECT_LE(b.summary["probes"]["total"].get<uint64_t>(), 20u);
  // The file's settings hold what the bake used.
  const CliResult info = run_gibake_cli("info " + shell_quote(file("draft_rays.gibake")) + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json settings = nlohmann::json::parse(info.out)["metadata"]["settings"];
  EXPECT_EQ(settings["rays"], 300);
  EXPECT_EQ(settings["max_rays"], 1024);  // the level's, with the given --rays
  EXPECT_EQ(settings["ray_budget"], 512);
  EXPECT_EQ(settings["grid"]["auto_cells"], 12);
  EXPECT_EQ(settings["grid"]["auto_max_probes"], 20);
  EXPECT_FALSE(settings.contains("probe_filter")) << settings.dump();  // draft's filter, turned off
}

nlohmann::json info_json(const std::string& path) {
  const CliResult info = run_gibake_cli("info " + shell_quote(path) + " --format json");
  EXPECT_EQ(info.exit_code, 0) << info.err;
  return nlohmann::json::parse(info.out, nullptr, false);
}

// --irradiance-atlas off leaves out the irradiance atlas and nothing else: every other section
// holds the bytes of the bake with the atlas, so the lit preview is the image the file with the
// atlas gives when the sampler reads the SH (preview --irradiance sh); the file is smaller by the
// atlases' bytes, and it verifies.
TEST_F(Quality, WithoutTheIrradianceAtlasOnlyTheAtlasIsLeftOut) {
  for (gibake::Quality q : {gibake::Quality::Draft, gibake::Quality::Default, gibake::Quality::Final})
    EXPECT_TRUE(gibake::quality_preset(q).irradiance_atlas) << gibake::quality_name(q);
  const Baked on = bake(file("on.gibake"), "");
  const Baked off = bake(file("off.gibake"), "--irradiance-atlas off");
  ASSERT_EQ(on.run.exit_code, 0) << on.run.err;
  ASSERT_EQ(off.run.exit_code, 0) << off.run.err;
  const std::string line = off.summary.value("quality", "");
  EXPECT_NE(line.find(", no irradiance atlas, probe filter off, surface fit off; given explicitly: --irradiance-atlas"),
            std::string::npos)
      << line;
  const nlohmann::json a = info_json(file("on.gibake")), b = info_json(file("off.gibake"));
  ASSERT_TRUE(a.is_object() && b.is_object());
  // The sections by type and checksum; the volume records (their irradiance width) and the
  // metadata (the settings) are the ones that may differ.
  auto kept = [](const nlohmann::json& info, uint64_t& atlas_bytes) {
    std::multiset<std::string> out;
    for (const nlohmann::json& s : info["sections"]) {
      const std::string type = s["type"];
      if (type == "ddgi_irradiance") atlas_bytes += s["size"].get<uint64_t>();
      if (type != "ddgi_irradiance" && type != "ddgi_volume" && type != "metadata")
        out.insert(type + " " + s["checksum"].get<std::string>());
    }
    return out;
  };
  uint64_t atlas_on = 0, atlas_off = 0;
  const std::multiset<std::string> sections_on = kept(a, atlas_on), sections_off = kept(b, atlas_off);
  EXPECT_GT(atlas_on, 0u);
  EXPECT_EQ(atlas_off, 0u);
  EXPECT_GE(sections_on.size(), 5u);  // SH, offsets, states, stats, depth: the grid's at least
  EXPECT_TRUE(sections_on == sections_off) << "a section other than the irradiance atlas changed";
  ASSERT_EQ(a["ddgi"].size(), b["ddgi"].size());
  for (const nlohmann::json& v : b["ddgi"]) {
    EXPECT_FALSE(v.contains("irradiance_atlas")) << v.dump();
    EXPECT_TRUE(v.contains("depth_atlas")) << v.dump();
  }
  EXPECT_EQ(b["metadata"]["settings"].value("irradiance_atlas", true), false);
  EXPECT_FALSE(a["metadata"]["settings"].contains("irradiance_atlas"));  // the default keeps its bytes
  const double saved =
      double(std::filesystem::file_size(file("on.gibake"))) - double(std::filesystem::file_size(file("off.gibake")));
  EXPECT_NEAR(saved, double(atlas_on), 4096.0);
  EXPECT_EQ(run_gibake_cli("verify " + shell_quote(file("off.gibake"))).exit_code, 0);
  auto lit = [&](const std::string& name, const std::string& bake, const std::string& source) {
    const CliResult r =
        run_gibake_cli("preview " + kSample + " --bake " + shell_quote(file(bake)) +
                       " --mode lit --size 64x48 --irradiance " + source + " --out " + shell_quote(file(name)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return read_text_file(file(name));
  };
  const std::string on_sh = lit("on_sh.png", "on.gibake", "sh"), off_sh = lit("off_sh.png", "off.gibake", "sh");
  const std::string on_atlas = lit("on_atlas.png", "on.gibake", "atlas");
  const std::string off_atlas = lit("off_atlas.png", "off.gibake", "atlas");
  ASSERT_FALSE(on_sh.empty());
  EXPECT_TRUE(on_sh == off_sh) << "the SH's picture changed without the irradiance atlas";
  EXPECT_TRUE(off_atlas == off_sh) << "without the atlas the sampler reads the SH";
  EXPECT_FALSE(on_atlas == on_sh) << "with the atlas the sampler reads it, not the SH";
}

std::string one_error(const std::string& args) { return usage_error_line(args); }

TEST_F(Quality, AMistypedLevelGetsTheNearestOne) {
  const std::string base = kSample + " --ddgi --out " + shell_quote(file("never.gibake"));
  EXPECT_EQ(one_error(base + " --quality finale"),
            "gibake: error: --quality: expected draft, default or final, got 'finale'; did you mean 'final'?");
  EXPECT_EQ(one_error(base + " --quality Draft"),
            "gibake: error: --quality: expected draft, default or final, got 'Draft'; did you mean 'draft'?");
  EXPECT_EQ(one_error(base + " --quality best"), "gibake: error: --quality: expected draft, default or final, got 'best'");
}

TEST_F(Quality, HelpShowsTheLevelWithItsDefault) {
  const CliResult r = run_gibake_cli("bake --help");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  bool found = false;
  for (const std::string& line : split_lines(r.out))
    if (line.find("--quality") != std::string::npos) {
      found = true;
      EXPECT_NE(line.find("[default: default]"), std::string::npos) << line;
      EXPECT_LT(line.size(), 100u) << line;
    }
  EXPECT_TRUE(found) << r.out;
}

}  // namespace
