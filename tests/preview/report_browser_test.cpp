// The bake report in a real headless browser (Debian's chromium): the page loads with no console
// errors, every image decodes (naturalWidth > 0), and a screenshot is not blank. Skipped with a
// message where no chromium is installed (scripts/setup.sh installs it for CI).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bake/preview/bake_report.h"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wuseless-cast"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace {

std::string find_browser() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"})
    if (access(p, X_OK) == 0) return p;
  return "";
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

int sh(const std::string& cmd) { return std::system(cmd.c_str()); }

TEST(BakeReport, LoadsInHeadlessChromium) {
  const std::string browser = find_browser();
  if (browser.empty()) GTEST_SKIP() << "no chromium installed (apt-get install chromium; scripts/setup.sh does)";
  char tmpl[] = "/tmp/gibake_report_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  const std::string bake = dir + "/cornell.gibake", report = dir + "/report.html";
  ASSERT_EQ(sh(std::string(GIBAKE_EXE) + " bake " + GIBAKE_SOURCE_DIR +
               "/samples/cornell/cornell.gltf --ddgi --rays 64 --progress lines --out " + bake + " --report " +
               report + " 2> " + dir + "/bake.log"),
            0);
  const std::string html = slurp(report);
  ASSERT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg")) << "no network references";
  const std::string flags = " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                            "--disable-background-networking --disable-component-update --disable-sync "
                            "--user-data-dir=" + dir + "/profile";
  // 1) The page itself: console errors are logged to stderr.
  sh("timeout 60 " + browser + flags + " --enable-logging=stderr --v=0 --window-size=1200,1600 --screenshot=" + dir +
     "/shot.png file://" + report + " > " + dir + "/chrome.log 2>&1");
  const std::string log = slurp(dir + "/chrome.log");
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  EXPECT_EQ(log.find("Refused to"), std::string::npos) << log;
  EXPECT_EQ(log.find(":ERROR:CONSOLE"), std::string::npos) << log;
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load((dir + "/shot.png").c_str(), &w, &h, &n, 3);
  ASSERT_NE(px, nullptr) << "no screenshot; chromium log:\n" << log;
  long distinct = 0;
  for (long i = 1; i < long(w) * h; ++i)
    if (px[i * 3] != px[0] || px[i * 3 + 1] != px[1] || px[i * 3 + 2] != px[2]) ++distinct;
  stbi_image_free(px);
  EXPECT_GT(distinct, long(w) * h / 20) << "screenshot is (nearly) blank";
  // 2) A copy with a script that records each image's decoded width into the DOM (--dump-dom).
  std::string probe = html;
  const size_t csp = probe.find("<meta http-equiv=\"Content-Security-Policy\"");
  if (csp != std::string::npos) probe.erase(csp, probe.find('>', csp) - csp + 1);
  probe.insert(probe.rfind("</body>"),
               "<script>window.addEventListener('load',function(){var r=[];"
               "document.querySelectorAll('img').forEach(function(i){r.push(i.naturalWidth)});"
               "var d=document.createElement('div');d.id='imgcheck';d.textContent='IM'+'GS='+r.join(',')+'=E'+'ND';"
               "document.body.appendChild(d);});</script>");
  std::ofstream(dir + "/probe.html") << probe;
  sh("timeout 60 " + browser + flags + " --virtual-time-budget=5000 --dump-dom file://" + dir + "/probe.html > " +
     dir + "/dom.html 2>/dev/null");
  const std::string dom = slurp(dir + "/dom.html");
  const size_t a = dom.find("IMGS="), b = dom.find("=END");
  ASSERT_TRUE(a != std::string::npos && b != std::string::npos) << "script result missing from the DOM";
  const std::string widths = dom.substr(a + 5, b - a - 5);
  std::printf("report images' naturalWidth: %s\n", widths.c_str());
  int images = 0;
  std::stringstream ss(widths);
  std::string item;
  while (std::getline(ss, item, ',')) {
    EXPECT_GT(std::atoi(item.c_str()), 0) << "an image did not decode";
    ++images;
  }
  EXPECT_EQ(images, 3);  // lit, probes, the reconstruction check's patches
  sh("rm -rf " + dir);
}

// The page's embedded PNGs, decoded (RGB).
struct Picture {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
};
std::vector<Picture> embedded_pictures(const std::string& html) {
  static const std::string kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<Picture> out;
  const std::string tag = "data:image/png;base64,";
  for (size_t at = html.find(tag); at != std::string::npos; at = html.find(tag, at + 1)) {
    std::vector<unsigned char> bytes;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = at + tag.size(); i < html.size() && html[i] != '"' && html[i] != '='; ++i) {
      acc = (acc << 6) | uint32_t(kTable.find(html[i]));
      bits += 6;
      if (bits >= 8) {
        bits -= 8;
        bytes.push_back(static_cast<unsigned char>((acc >> bits) & 0xff));
      }
    }
    Picture p;
    int n = 0;
    unsigned char* px = stbi_load_from_memory(bytes.data(), int(bytes.size()), &p.w, &p.h, &n, 3);
    if (!px) continue;
    p.rgb.assign(px, px + size_t(p.w) * size_t(p.h) * 3);
    stbi_image_free(px);
    out.push_back(std::move(p));
  }
  return out;
}

// A bake of several volumes (the default's refined volumes among them): the page lists every
// volume with its counts and the totals, and the grid and probe sections say that they are volume
// 0's, whose figures they give, rather than reading as the whole bake's.
TEST(BakeReport, SeveralVolumesAreListedWithTheirTotals) {
  std::vector<gibake::BakedVolume> volumes(2);
  const int32_t counts[2][3] = {{4, 3, 2}, {2, 2, 2}};
  for (size_t v = 0; v < 2; ++v) {
    gibake::DdgiVolumeDesc& d = volumes[v].result.desc;
    for (int a = 0; a < 3; ++a) d.counts[size_t(a)] = counts[v][a], d.spacing[size_t(a)] = v ? 0.5f : 1.f;
    volumes[v].report.probes = d.probe_count();
    volumes[v].report.active = d.probe_count() - 1 - int32_t(v);
    volumes[v].report.inactive = 1 + int32_t(v);
    volumes[v].report.primary_rays = 1000 * (v + 1);
  }
  volumes[1].kind = gibake::VolumeKind::Refined;
  gibake::BakeReportInputs in;
  in.result = &volumes[0].result;
  in.report = &volumes[0].report;
  in.volumes = &volumes;
  const std::string html = gibake::bake_report_html(in);
  EXPECT_NE(html.find("<h2>Probe volumes</h2><p>2 volumes; the grid, probe and ray sections below are volume 0's."),
            std::string::npos);
  EXPECT_NE(html.find("<tr><td>volume 1 (refined): 2x2x2 = 8 probes, spacing 0.5 m, 6 active; </td>"
                      "<td class=\"n\">8</td><td class=\"n\">6</td><td class=\"n\">2</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<tr><td>all volumes</td><td class=\"n\">32</td><td class=\"n\">29</td>"
                      "<td class=\"n\">3</td><td class=\"n\">0</td><td class=\"n\">3000</td></tr>"),
            std::string::npos);
  EXPECT_NE(html.find("<h2>Probe grid (volume 0)</h2><p>4 x 3 x 2 = 24 probes"), std::string::npos);
  EXPECT_NE(html.find("<h2>Probes (volume 0)</h2>"), std::string::npos);
  in.volumes = nullptr;  // one volume: the sections are the bake's
  EXPECT_NE(gibake::bake_report_html(in).find("<h2>Probe grid</h2>"), std::string::npos);
}

// The report on Sponza: it states the grid, its own time and the total, says
// what rays per probe count, gives one inactive count, shows settings without placeholders or float
// noise, tone-maps the sunlit floor instead of clipping it, hides probes behind the floor, and lists
// every leak-audit region while the bake warns about a few. --max-rays 512 stops the adaptive passes
// at the fewest rays a probe takes here (the minimum the report states): the grid, ray, inactive and
// leak figures checked are the uncapped bake's.
TEST(BakeReport, TellsTheGridTimesRaysAndDoesNotClip) {
  char tmpl[] = "/tmp/gibake_report_sponza_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  const std::string bake = dir + "/sponza.gibake", report = dir + "/report.html";
  ASSERT_EQ(sh(std::string(GIBAKE_EXE) + " " + GIBAKE_ASSETS_DIR + "/sponza/Sponza.gltf --ddgi --sun 0.3,-1,0.2:100000 "
               "--probe-spacing 3.18934 --max-rays 512 --progress lines --out " + bake + " --report " + report + " 2> " + dir + "/bake.log"),
            0);
  const std::string html = slurp(report), log = slurp(dir + "/bake.log");
  EXPECT_NE(html.find("<h2>Probe grid</h2><p>16 x 7 x 10 = 1120 probes, spacing 3.189 x 3.189 x 3.189 m"),
            std::string::npos);
  EXPECT_NE(html.find("<td>report</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>total</td>"), std::string::npos);
  EXPECT_NE(html.find("Rays per probe, relocation rays included (128 per probe): min 640"), std::string::npos);
  const std::string settings = html.substr(html.find("<h2>Settings</h2>"));
  EXPECT_EQ(settings.find("\"counts\""), std::string::npos);
  EXPECT_EQ(settings.find("0.30000001"), std::string::npos);
  EXPECT_EQ(html.find("without being enclosed"), std::string::npos);  // the second, different inactive count
  EXPECT_NE(html.find("812 probes are inactive: 586 in enclosed unlit space"), std::string::npos);
  const std::vector<Picture> pictures = embedded_pictures(html);
  ASSERT_EQ(pictures.size(), 3u);  // lit, probes, and the reconstruction check's patches over lit
  // The reconstruction check's figures, its worst patches, and where they lie.
  EXPECT_NE(html.find("<h2>Reconstruction error</h2><p>reconstruction error (probes' view, "), std::string::npos);
  EXPECT_NE(html.find("within 10% of the path-traced truth"), std::string::npos);
  EXPECT_NE(html.find("<h3>Worst patches</h3>"), std::string::npos);
  ASSERT_EQ(pictures[2].rgb.size(), pictures[0].rgb.size());
  size_t marked = 0;
  for (size_t i = 0; i < pictures[0].rgb.size(); ++i) marked += pictures[0].rgb[i] != pictures[2].rgb[i];
  EXPECT_GT(marked, 100u) << "no patch marked on the lit view";
  auto fraction = [](const Picture& p, auto&& pred) {
    size_t n = 0;
    for (size_t i = 0; i + 2 < p.rgb.size(); i += 3) n += pred(&p.rgb[i]);
    return double(n) / double(size_t(p.w) * size_t(p.h));
  };
  const double clipped = fraction(pictures[0], [](const unsigned char* c) { return c[0] == 255 || c[1] == 255 || c[2] == 255; });
  EXPECT_LT(clipped, 0.01) << "the lit picture clips the sunlit floor";
  const double magenta =
      fraction(pictures[1], [](const unsigned char* c) { return c[0] > 200 && c[1] < 60 && c[2] > 200; });
  EXPECT_LT(magenta, 0.02) << "inactive probes drawn through the floor and walls";
  // Leak audit: every region in the report, at most three named warnings in the bake.
  const std::string leaks = html.substr(html.find("<h2>Leak audit</h2>"));
  size_t listed = 0;
  for (size_t at = leaks.find("<li>"); at != std::string::npos; at = leaks.find("<li>", at + 1)) ++listed;
  EXPECT_EQ(listed, 16u);  // the audit of this grid (3.18934 m) finds 16 thin-wall regions
  size_t warned = 0;
  for (size_t at = log.find("warning: leak risk: wall"); at != std::string::npos;
       at = log.find("warning: leak risk: wall", at + 1))
    ++warned;
  EXPECT_GE(warned, 1u);
  EXPECT_LE(warned, 3u) << log;
  EXPECT_NE(log.find(" across it, up to "), std::string::npos) << log;
  sh("rm -rf " + dir);
}

}  // namespace
