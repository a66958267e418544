#pragma once
// A report as data: what the workpiece, machine, drift, monitor and surface reports say (headings,
// paragraphs, tables, lists, the "load onto the control" box, figures of plotted series, notes),
// built by each library from its results and rendered by ONE module (core/report_render.h: HTML
// with one stylesheet, gnuplot for the figures). A library never writes markup or gnuplot
// commands itself; it names what to show:
//   - text is plain text (never markup): the renderer escapes every string (HtmlEscape,
//     GnuplotString), so a screw name or a column header can hold anything;
//   - a plotted series names its look by key (`style`: a strategy, drift method or monitor rule
//     of core/plot_style.h), so one strategy has one colour and dash in every report, and the
//     legend beside each figure is drawn from the same table;
//   - columns of a data file are numbers (1-based, gnuplot's $n), never expressions.
#include <cmath>
#include <string>
#include <vector>

namespace whirl::report {

/// A piece of a paragraph: plain, bold, code, or a link (`href` relative to the page).
struct Span {
  enum class Kind { kText, kBold, kCode, kLink };
  Kind kind = Kind::kText;
  std::string text;
  std::string href;
};
Span Text(std::string text);
Span Bold(std::string text);
Span Code(std::string text);
Span Link(std::string href, std::string text);

enum class Tone { kNormal, kSmall, kWarn };

struct Paragraph {
  std::vector<Span> spans;
  Tone tone = Tone::kNormal;
};

struct Heading {
  int level = 2;  ///< 2 or 3 (the page's title is the one level-1 heading)
  std::string text;
  std::string id;  ///< anchor, "" for none
};

struct Cell {
  Cell(std::string t = {}) : text(std::move(t)) {}  // NOLINT: a cell is its text
  Cell(const char* t) : text(t) {}                   // NOLINT
  std::string text;
  int colspan = 1;
  bool left = false;  ///< left-aligned (numbers are right-aligned)
  /// In a table of series (Table::series_rows): this row names no plotted series (a baseline
  /// shown in the table only).
  bool not_plotted = false;
};

struct Table {
  std::vector<std::string> header;  ///< column names with units, e.g. "within 1000 mm [um]"
  std::vector<std::vector<Cell>> rows;
  std::vector<std::size_t> highlight;  ///< rows shown bold (e.g. the model's)
  std::string caption;                 ///< small print below, "" for none
  /// The first column names series looks (strategies, methods, rules of core/plot_style.h): the
  /// page marks each such cell with data-series, so a test can match the legends against it.
  bool series_rows = false;
};

struct List {
  std::vector<std::vector<Span>> items;
  Tone tone = Tone::kNormal;
};

/// Preformatted text (an NC line, a program's output), wrapped to the page.
struct Preformatted {
  std::string text;
};

/// One column of a data file as gnuplot reads it: `$index`, or `$index + $plus - $minus`, divided
/// by `divide` (e.g. minutes to hours: 60), plus the constant `add` (e.g. a band's -sd or +sd
/// around a prediction's column); `only_if_column` > 0: only rows whose column holds
/// `only_if_value` (others are left out).
struct Column {
  int index = 1;
  int plus = 0;
  int minus = 0;
  double divide = 1;
  double add = 0;
  int only_if_column = 0;
  double only_if_value = 0;
};
Column Col(int index, double divide = 1);
/// The column `index` plus the constant `add` (a band's edge: Shifted(k, -sd), Shifted(k, sd)).
Column Shifted(int index, double add);

enum class SeriesKind {
  kLine,        ///< a line in the look of `style` (core/plot_style.h)
  kBand,        ///< the filled region between two columns (columns: x, low, high)
  kPoints,      ///< filled points
  kOpenPoints,  ///< open circles
  kLinePoints,  ///< a line with filled squares at the data
  kMap,         ///< a colour map of z over x, y (columns: x, y, z; the file a grid with blank lines)
  kContour,     ///< contour lines of the same grid
  kImage,       ///< a matrix as an image (columns: i, j, value)
};

struct Series {
  std::string file;  ///< data file relative to the page (CSV, or whitespace for maps)
  int block = -1;    ///< gnuplot `index` of a file of blocks; -1: the whole file
  std::vector<Column> columns;
  SeriesKind kind = SeriesKind::kLine;
  /// The look's key in core/plot_style.h (a strategy, method or rule; "measured", "prediction",
  /// "residual"); "" takes `colour` and `width` below (unnamed series such as sensors).
  std::string style;
  std::string colour;  ///< "#rrggbb" when `style` is ""
  double width = 1.5;  ///< line width when `style` is ""
  bool right_axis = false;
  /// The legend's words ("" leaves the series out of the legend, e.g. markers of a rule's checks).
  std::string title;
  /// Open circles at 40 places along a line: how a series that coincides with one drawn before
  /// it stays visible (a dash pattern vanishes under another line).
  bool markers = false;
};

/// The +-`sd` band of the prediction in column `y` of `file` over `x`, in the look `style`.
Series SdBand(std::string file, Column x, int y, double sd, std::string style, std::string title);

struct Range {
  double low = NAN, high = NAN;  ///< NaN: chosen by gnuplot
};

struct Panel {
  std::string title, xlabel, ylabel, y2label, cblabel;
  Range x, y;
  bool y2_log = false;
  bool y_reversed = false;
  bool equal_axes = false;              ///< one unit is as long on x as on y (maps, matrices)
  std::vector<std::string> tic_names;   ///< names of the integer tics 0.. on both axes (matrices)
  std::vector<double> x_marks;          ///< dashed vertical lines (e.g. end of training)
  std::vector<double> y2_marks;         ///< dashed horizontal lines on the right axis
  std::vector<Series> series;
};

/// A picture of one or more panels: `stem`.png drawn by `stem`.gp, shown with a legend beside it
/// (the titled series of every panel, each once, in its look).
struct Figure {
  std::string stem;  ///< file name without extension: slug-safe (core/safe_text.h Slug)
  std::string alt;   ///< what the picture shows (alt text)
  std::string title;  ///< over all panels ("" for none)
  int width_px = 1000, height_px = 480;
  int columns = 1;  ///< panels per row
  std::vector<Panel> panels;
};

struct Block;

/// A framed section: the "load onto the control" box (class "control", id "load").
struct Box {
  std::string id;  ///< e.g. "load"
  std::vector<Block> blocks;
};

struct Block {
  enum class Kind { kHeading, kParagraph, kTable, kList, kPreformatted, kFigure, kBox };
  Kind kind = Kind::kParagraph;
  Heading heading;
  Paragraph paragraph;
  Table table;
  List list;
  Preformatted pre;
  Figure figure;
  Box box;
};

/// A page: its title (the one <h1>), provenance lines (the command, the model, the seed), blocks.
struct Document {
  std::string title;
  std::vector<std::string> provenance;
  std::vector<Block> blocks;

  Document& Add(Heading h);
  Document& Add(Paragraph p);
  Document& Add(Table t);
  Document& Add(List l);
  Document& Add(Preformatted p);
  Document& Add(Figure f);
  Document& Add(Box b);
  Document& Add(const std::vector<Block>& blocks);
  /// A paragraph of plain text.
  Document& Say(std::string text, Tone tone = Tone::kNormal);
};

Block MakeBlock(Heading h);
Block MakeBlock(Paragraph p);
Block MakeBlock(Table t);
Block MakeBlock(List l);
Block MakeBlock(Preformatted p);
Block MakeBlock(Figure f);
Block MakeBlock(Box b);

}  // namespace whirl::report
