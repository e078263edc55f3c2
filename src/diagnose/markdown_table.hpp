#pragma once
// Markdown tables and number formatting shared by the diagnosis reports (catalogue, timing,
// appearance), so every summary.md table is written the same way.
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace spinradar::diagnose {

/// Number with `prec` significant digits (stream default notation).
inline std::string fmt(double v, int prec = 4) {
  std::ostringstream s;
  s << std::setprecision(prec) << v;
  return s.str();
}

/// Header, separator and one line per row: "| a | b |". Cells are streamed with the given
/// precision (significant digits), so numbers and strings can be mixed in one row.
class MarkdownTable {
 public:
  explicit MarkdownTable(const std::vector<std::string>& header, int precision = 6)
      : precision_(precision) {
    std::string sep = "|";
    text_ = "|";
    for (const auto& h : header) {
      text_ += " " + h + " |";
      sep += "---|";
    }
    text_ += "\n" + sep + "\n";
  }

  template <class... Cells>
  MarkdownTable& row(const Cells&... cells) {
    std::ostringstream s;
    s << std::setprecision(precision_) << "|";
    ((s << " " << cells << " |"), ...);
    text_ += s.str() + "\n";
    return *this;
  }

  const std::string& str() const { return text_; }

 private:
  int precision_;
  std::string text_;
};

}  // namespace spinradar::diagnose
