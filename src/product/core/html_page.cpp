#include "core/html_page.h"

#include "core/safe_text.h"

namespace whirl {

std::string_view ReportStylesheet() {
  return "body{font-family:sans-serif;max-width:1100px;margin:1.5em auto;padding:0 1em;color:#222;"
         "line-height:1.4}\n"
         "h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}\n"
         "table{border-collapse:collapse;margin:0.6em 0;display:block;overflow-x:auto;"
         "max-width:100%}\n"
         "td,th{border:1px solid #bbb;padding:3px 8px;text-align:right;vertical-align:top}\n"
         "td:first-child,th:first-child{text-align:left}th{background:#eee}\n"
         "tr.cls td{font-weight:bold}\n"
         ".small{font-size:0.85em;color:#555}.warn{color:#a00}\n"
         ".control{border:2px solid #2a6;background:#f3fbf5;padding:0.4em 1.2em 0.8em;"
         "margin:1em 0;border-radius:6px}\n"
         ".control h2{border:none;margin-top:0.5em}\n"
         "pre,code{font-family:monospace;font-size:0.9em}\n"
         "pre{background:#f6f6f6;padding:6px;white-space:pre-wrap;overflow-wrap:anywhere}\n"
         "img{max-width:100%;height:auto;border:1px solid #ddd;display:block;margin:0.5em 0}\n"
         "figure{margin:0.8em 0}\n"
         ".legend{list-style:none;padding:0;margin:0.2em 0 1em;columns:2 24em;font-size:0.9em}\n"
         ".legend li{break-inside:avoid;margin:0.1em 0}"
         ".legend svg{vertical-align:middle;margin-right:0.5em}\n";
}

std::string HtmlPageBegin(std::string_view title, const std::vector<std::string>& provenance) {
  std::string h =
      "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
      "<meta name='viewport' content='width=device-width, initial-scale=1'><title>" +
      HtmlEscape(title) + "</title>\n<style>\n" + std::string(ReportStylesheet()) +
      "</style></head><body>\n<h1>" + HtmlEscape(title) + "</h1>\n";
  for (const auto& p : provenance) h += "<p class='small'>" + HtmlEscape(p) + "</p>\n";
  return h;
}

std::string HtmlPageEnd() { return "</body></html>\n"; }

std::string HtmlImage(std::string_view file, std::string_view alt) {
  return "<img src='" + HtmlEscape(file) + "' alt='" + HtmlEscape(alt) + "'>";
}

std::string HtmlLink(std::string_view href, std::string_view text) {
  return "<a href='" + HtmlEscape(href) + "'>" + HtmlEscape(text) + "</a>";
}

}  // namespace whirl
