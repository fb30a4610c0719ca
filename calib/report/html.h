#pragma once
// A self-contained HTML page for reports a person reads (doc/check.md, "The report"): one file,
// its style inline, its figures inline SVG, no script, nothing fetched. Built from the steps'
// saved JSON and figures, so `rigcal report DIR` renders it again from what a run stored.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/report/svg_plot.h"

namespace rigcal::report {

// A JSON number as text by `format` (fmt's), times `scale`; "-" where it is not a number (null
// for NaN, or absent).
std::string html_number(const nlohmann::json& value, const char* format, double scale = 1.0);

// Text as HTML (& < > " ').
std::string html_escape(std::string_view text);

// A table: a header row, then rows of cells that are HTML already (escape text first).
// `classes`: a CSS class a row ("" for none), as long as `rows` or empty.
std::string html_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows,
                       const std::vector<std::string>& classes = {});

// A verdict as a coloured badge: "consistent" and "ok" green, "changed", "failed" red, others
// (cannot tell, undetermined, blocked) amber.
std::string html_badge(std::string_view verdict);

// The whole page: <!doctype html>, the title, the style, `body`.
std::string html_page(std::string_view title, std::string_view body);

// An SVG file's text ready to sit inline in a page (its XML declaration dropped).
std::string html_inline_svg(std::string_view svg);

// An image file's bytes (PNG, or anything OpenCV decodes) as an <img> inside the page: at most
// `max_width` pixels wide (scaled down by area), as a JPEG of quality 90 in a base64 data URI,
// so that a page with a dozen camera images stays a few MB. Throws rigcal::Error when the bytes
// are no image.
std::string html_inline_image(std::string_view bytes, std::string_view alt, int max_width = 1000);

// <figure>: its content and its caption (both HTML already), then a newline.
std::string html_figure(std::string_view content, std::string_view caption);
// A plot (svg_plot.h) as an inline SVG figure with its caption (HTML).
std::string html_plot_figure(const Plot& plot, std::string_view caption);

}  // namespace rigcal::report
