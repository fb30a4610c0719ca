// A self-contained HTML page (html.h).
#include "rigcal/report/html.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "rigcal/core/error.h"
#include "rigcal/core/sha256.h"

namespace rigcal::report {

std::string html_number(const nlohmann::json& v, const char* format, double scale) {
  if (!v.is_number()) return "-";
  return fmt::format(fmt::runtime(format), scale * v.get<double>());
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string html_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows,
                       const std::vector<std::string>& classes) {
  std::string out = "<table>\n<thead><tr>";
  for (const std::string& h : header) out += "<th>" + html_escape(h) + "</th>";
  out += "</tr></thead>\n<tbody>\n";
  for (size_t r = 0; r < rows.size(); ++r) {
    const std::string cls = r < classes.size() && !classes[r].empty()
                                ? fmt::format(" class=\"{}\"", html_escape(classes[r]))
                                : "";
    out += "<tr" + cls + ">";
    for (const std::string& cell : rows[r]) out += "<td>" + cell + "</td>";
    out += "</tr>\n";
  }
  return out + "</tbody>\n</table>\n";
}

std::string html_badge(std::string_view verdict) {
  const std::string_view kind = verdict == "consistent" || verdict == "ok"    ? "good"
                                : verdict == "changed" || verdict == "failed" ? "bad"
                                                                              : "unsure";
  return fmt::format("<span class=\"badge {}\">{}</span>", kind, html_escape(verdict));
}

std::string html_page(std::string_view title, std::string_view body) {
  return fmt::format(
      "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>{}</title>\n<style>\n"
      "body {{ font-family: sans-serif; margin: 2em auto; max-width: 1100px; color: #222; "
      "line-height: 1.4; }}\n"
      "h1 {{ font-size: 1.6em; }} h2 {{ font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px "
      "solid #ccc; }}\n"
      "table {{ border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }}\n"
      "th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; "
      "vertical-align: top; }}\n"
      "th {{ background: #f2f2f2; }}\n"
      "td.num {{ text-align: right; font-variant-numeric: tabular-nums; }}\n"
      ".badge {{ padding: 0.1em 0.5em; border-radius: 0.6em; font-weight: bold; white-space: "
      "nowrap; }}\n"
      ".good {{ background: #d7f2d7; color: #185c18; }} .bad {{ background: #f8d4d4; color: "
      "#8a1616; }} .unsure {{ background: #fbeccc; color: #7a5200; }}\n"
      ".headline {{ font-size: 1.25em; padding: 0.6em 0.9em; border-radius: 0.4em; }}\n"
      ".note {{ color: #555; font-size: 0.9em; }}\n"
      "figure {{ margin: 1em 0; }} figcaption {{ color: #555; font-size: 0.9em; }}\n"
      "figure img {{ max-width: 100%; }} pre {{ font-size: 0.85em; white-space: pre-wrap; }}\n"
      "ul.warning, p.warning {{ background: #fbeccc; color: #5a3c00; padding: 0.5em 0.5em 0.5em "
      "1.8em; border-radius: 0.4em; }} p.warning {{ padding-left: 0.9em; }}\n"
      "tr.bad td {{ background: #fdf0f0; }}\n"
      "</style>\n</head>\n<body>\n{}\n</body>\n</html>\n",
      html_escape(title), body);
}

std::string html_inline_svg(std::string_view svg) {
  const size_t start = svg.find("<svg");
  std::string out(start == std::string_view::npos ? svg : svg.substr(start));
  // Ids are page-wide: the plots' clip path gets one of its own, from the figure's content.
  const std::string id = "area-" + sha256_hex(out).substr(0, 12);
  for (const std::string_view from : {"id=\"area\"", "url(#area)"}) {
    const std::string to = from[0] == 'i' ? "id=\"" + id + "\"" : "url(#" + id + ")";
    for (size_t at = out.find(from); at != std::string::npos; at = out.find(from, at + to.size()))
      out.replace(at, from.size(), to);
  }
  return out;
}

std::string html_figure(std::string_view content, std::string_view caption) {
  return fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n", content, caption);
}

std::string html_plot_figure(const Plot& plot, std::string_view caption) {
  return html_figure(html_inline_svg(render_svg(plot)), caption);
}

std::string html_inline_image(std::string_view bytes, std::string_view alt, int max_width) {
  const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8U,
                    const_cast<char*>(bytes.data()));  // read only
  cv::Mat image = cv::imdecode(raw, cv::IMREAD_COLOR);
  if (image.empty()) throw Error(fmt::format("{}: not an image OpenCV decodes", alt));
  if (image.cols > max_width) {
    cv::Mat small;
    cv::resize(image, small, cv::Size(max_width, image.rows * max_width / image.cols), 0, 0,
               cv::INTER_AREA);
    image = small;
  }
  std::vector<uchar> jpeg;
  if (!cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}))
    throw Error(fmt::format("{}: JPEG encoding failed", alt));
  const std::string_view data(reinterpret_cast<const char*>(jpeg.data()), jpeg.size());
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  b64.reserve((data.size() + 2) / 3 * 4);
  for (size_t i = 0; i < data.size(); i += 3) {
    const size_t n = std::min<size_t>(3, data.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k)
      v = v << 8 | (k < n ? static_cast<unsigned char>(data[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) b64 += k <= n ? kDigits[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return fmt::format("<img src=\"data:image/jpeg;base64,{}\" width=\"{}\" alt=\"{}\">", b64,
                     image.cols, html_escape(alt));
}

}  // namespace rigcal::report
