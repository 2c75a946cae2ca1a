#pragma once
// Loads an HTML page in headless Chromium (Debian's `chromium`) and reports what a reader would
// see: console errors, each <img>'s decoded width (naturalWidth; 0 = not decoded), and a
// screenshot. Absent Chromium is a failure with a clear message, not a skip (CI installs it
// with scripts/setup.sh).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/e2e/run.h"

namespace igi::test {

struct PageCheck {
  bool chromium_found = false;
  std::vector<int> image_widths;  // naturalWidth of every <img>, in page order
  std::vector<std::string> console_errors;
  std::filesystem::path screenshot;
};

inline std::string FindChromium() {
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    const std::string cmd = std::string("command -v ") + name + " >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return name;
  }
  return "";
}

// Copies `page` to `work` with a script that writes the images' naturalWidth into the DOM after
// load, dumps the DOM and takes a screenshot.
inline PageCheck CheckPageInChromium(const std::filesystem::path& page,
                                     const std::filesystem::path& work) {
  PageCheck check;
  const std::string chromium = FindChromium();
  check.chromium_found = !chromium.empty();
  if (!check.chromium_found) return check;
  std::filesystem::create_directories(work);
  std::ifstream in(page);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string html = ss.str();
  const std::string probe =
      "<script>window.addEventListener('load', function() {"
      " var w = []; document.querySelectorAll('img').forEach(function(i) {"
      " w.push(i.complete ? i.naturalWidth : 0); });"
      " var p = document.createElement('pre'); p.id = 'igi-probe';"
      " p.textContent = 'IMG_WIDTHS:' + w.join(',') + ':END'; document.body.appendChild(p);"
      "});</script>";
  const size_t body_end = html.rfind("</body>");
  html.insert(body_end == std::string::npos ? html.size() : body_end, probe);
  const auto probed = work / "probed.html";
  std::ofstream(probed) << html;
  const std::string flags =
      " --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=10000"
      " --enable-logging=stderr --v=0 ";
  const auto dom = work / "dom.html", log = work / "chromium.log";
  std::string cmd = chromium + flags + "--dump-dom " + Quote("file://" + probed.string()) + " >" +
                    Quote(dom.string()) + " 2>" + Quote(log.string());
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  check.screenshot = work / "screenshot.png";
  cmd = chromium + flags + "--window-size=1280,2400 --screenshot=" +
        Quote(check.screenshot.string()) + " " + Quote("file://" + page.string()) + " 2>>" +
        Quote(log.string()) + " >/dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream dom_in(dom);
  std::stringstream dom_text;
  dom_text << dom_in.rdbuf();
  const std::string d = dom_text.str();
  // The probe script's own text also holds "IMG_WIDTHS:"; its output is the last occurrence.
  const auto a = d.rfind("IMG_WIDTHS:"), b = d.find(":END", a == std::string::npos ? 0 : a);
  if (a != std::string::npos && b != std::string::npos) {
    std::stringstream list(d.substr(a + 11, b - a - 11));
    std::string item;
    while (std::getline(list, item, ',')) {
      if (!item.empty()) check.image_widths.push_back(std::stoi(item));
    }
  }
  std::ifstream log_in(log);
  std::string line;
  while (std::getline(log_in, line)) {
    if (line.find("CONSOLE") != std::string::npos &&
        (line.find("Uncaught") != std::string::npos || line.find("rror") != std::string::npos)) {
      check.console_errors.push_back(line);
    }
  }
  return check;
}

}  // namespace igi::test
