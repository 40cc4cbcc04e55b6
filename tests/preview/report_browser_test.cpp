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
  EXPECT_EQ(images, 2);
  sh("rm -rf " + dir);
}

}  // namespace
