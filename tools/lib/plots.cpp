// plots.cpp - dependency-free SVG plots for `pmfit explain` (host side).
#include "plots.hpp"
#include "plots.h"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

namespace pmplot {
namespace {

const char *const FONT = "DejaVu Sans, Helvetica, Arial, sans-serif";
// Okabe-Ito, with its yellow darkened to olive so that it shows on white.
const char *const COLOUR[8] = {"#0072B2", "#D55E00", "#009E73", "#E69F00",
                               "#CC79A7", "#56B4E9", "#999933", "#000000"};
// White outline behind text drawn over data.
const char *const HALO = " stroke=\"#ffffff\" stroke-width=\"4\" stroke-linejoin=\"round\" paint-order=\"stroke\"";
const char *const GRID = "#e6e6e6", *const INK = "#333333", *const FRAME = "#555555";
const double REF_PX = 40.0;  // length of the reference arrow of vector plots
const double ANGLE_STEP[] = {10, 15, 30, 45, 90, 180};

bool fin(double v) { return std::isfinite(v); }
const char *colour(int i) { return COLOUR[((i % 8) + 8) % 8]; }

using pmhost::fmt;
using pmhost::xml_escape;

// Approximate width in pixels of text in a DejaVu-like sans-serif font.
double text_w(const std::string &s, double size)
{
    size_t n = 0;
    for (unsigned char c : s)
        n += (c & 0xC0) != 0x80;
    return 0.6 * size * (double)n;
}

// A value for a label, with as many decimals as the spacing `step` needs.
std::string label_num(double v, double step)
{
    if (std::fabs(v) < 1e-9 * step) v = 0.0;
    double a = std::max(std::fabs(v), step);
    if (a >= 1e6 || step < 1e-4) return fmt("%.3g", v);
    int dec = step >= 1.0 ? 0 : (int)std::ceil(-std::log10(step) - 1e-9);
    return fmt("%.*f", dec, v);
}

// The SVG document under construction.
struct Svg {
    std::string s;
    int clips = 0;
    Svg(int w, int h, const std::string &title)
    {
        s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
        s += fmt("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
                 "font-family=\"%s\">\n", w, h, w, h, FONT);
        s += "<title>" + xml_escape(title) + "</title>\n";
        s += fmt("<rect x=\"0\" y=\"0\" width=\"%d\" height=\"%d\" fill=\"#ffffff\"/>\n", w, h);
        if (!title.empty())
            text(w / 2.0, 30, title, 18, "middle", "#111111", " font-weight=\"bold\"");
    }
    void text(double x, double y, const std::string &t, double size, const char *anchor = "middle",
              const char *fill = INK, const std::string &extra = "")
    {
        s += fmt("<text x=\"%.1f\" y=\"%.1f\" font-size=\"%g\" text-anchor=\"%s\" fill=\"%s\"", x, y, size, anchor, fill);
        s += extra + ">" + xml_escape(t) + "</text>\n";
    }
    void line(double x1, double y1, double x2, double y2, const char *stroke, double w, const std::string &extra = "")
    {
        s += fmt("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"%g\"",
                 x1, y1, x2, y2, stroke, w) + extra + "/>\n";
    }
    void rect(double x, double y, double w, double h, const char *fill, const std::string &extra = "")
    {
        s += fmt("<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%s\"", x, y, w, h, fill) + extra + "/>\n";
    }
};

// An arrow from (x, y) to (ex, ey) as one path (shaft and filled head), for a <g> that sets
// stroke and fill; nothing when shorter than half a pixel.
std::string arrow(double x, double y, double ex, double ey)
{
    double dx = ex - x, dy = ey - y, len = std::hypot(dx, dy);
    if (!(len >= 0.5)) return "";
    double h = std::min(7.0, 0.4 * len + 1.5), w = 0.42 * h, ux = dx / len, uy = dy / len;
    double bx = ex - ux * h, by = ey - uy * h;
    return fmt("<path d=\"M%.1f %.1fL%.1f %.1fM%.1f %.1fL%.1f %.1fL%.1f %.1fZ\"/>\n", x, y, bx + ux, by + uy,
               ex, ey, bx - uy * w, by + ux * w, bx + uy * w, by - ux * w);
}

// A plot axis: data [lo, hi] onto pixels [p0, p1] (p1 < p0 for y).
struct Axis {
    double lo = 0, hi = 1, p0 = 0, p1 = 1;
    bool log = false, angular = false, grid = true;
    double map(double v) const
    {
        double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
        return p0 + t * (p1 - p0);
    }
    double px() const { return std::fabs(p1 - p0); }
};

// Data extent [mn, mx] (mn > mx when empty) padded by a fraction of the span.
void set_range(Axis &a, double mn, double mx, double pad)
{
    if (!(mn <= mx)) { a.lo = a.log ? 1 : 0; a.hi = a.log ? 1000 : 1; return; }
    if (a.log) {
        double l0 = std::log10(mn), l1 = std::log10(mx), d = l1 > l0 ? (l1 - l0) * pad : 0.3;
        a.lo = std::pow(10.0, l0 - d); a.hi = std::pow(10.0, l1 + d);
        return;
    }
    double d = mx > mn ? (mx - mn) * pad : (mn != 0 ? std::fabs(mn) * 0.1 : 1.0);
    a.lo = mn - d; a.hi = mx + d;
}

struct Tick { double v; std::string label; bool major; };

// 1-2-5 steps (angular axes: 10, 15, 30, 45, 90 deg when the step is that large), about one
// per `spacing` pixels; log axes: decades, with 2 and 5 labelled when few decades show.
std::vector<Tick> ticks(const Axis &a, double spacing)
{
    std::vector<Tick> t;
    if (a.log) {
        double l0 = std::log10(a.lo), l1 = std::log10(a.hi);
        int k0 = (int)std::floor(l0), k1 = (int)std::ceil(l1), every = std::max(1, (int)std::ceil((l1 - l0) / 8));
        bool few = l1 - l0 < 2.2;
        for (int k = k0; k <= k1; k++)
            for (int m = 1; m <= 9; m++) {
                double v = m * std::pow(10.0, k);
                if (v < a.lo * (1 - 1e-9) || v > a.hi * (1 + 1e-9)) continue;
                bool lab = (m == 1 && k % every == 0) || (few && (m == 2 || m == 5));
                if (m == 1 || lab || l1 - l0 < 6)
                    t.push_back({v, lab ? fmt("%g", v) : "", lab});
            }
        return t;
    }
    double raw = (a.hi - a.lo) / std::max(2.0, a.px() / spacing), step = 0;
    if (a.angular && raw > 7.5 && raw < 180)
        for (double c : ANGLE_STEP)
            if (step == 0 && c >= raw * 0.75) step = c;
    if (step == 0) {
        double mag = std::pow(10.0, std::floor(std::log10(raw))), f = raw / mag;
        step = (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
    }
    for (double i = std::ceil(a.lo / step - 1e-9); i * step <= a.hi + 1e-9 * step && t.size() < 60; i++)
        t.push_back({i * step, label_num(i * step, step), true});
    return t;
}

// The plot area: frame in pixels, axes, and what goes around it.
struct Panel {
    double x0, y0, x1, y1;
    Axis ax, ay;
    std::string clip;
    bool zero_line = true;
    Panel(Svg &g, double l, double t, double r, double b) : x0(l), y0(t), x1(r), y1(b)
    {
        ax.p0 = x0; ax.p1 = x1; ay.p0 = y1; ay.p1 = y0;
        clip = fmt("clip%d", g.clips++);
    }
    bool inside(double x, double y) const { return x >= x0 - 0.5 && x <= x1 + 0.5 && y >= y0 - 0.5 && y <= y1 + 0.5; }
    // Grid (and the zero line) under the data; then opens a group clipped to the frame.
    void under(Svg &g) const
    {
        g.s += fmt("<defs><clipPath id=\"%s\"><rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\"/></clipPath></defs>\n",
                   clip.c_str(), x0, y0, x1 - x0, y1 - y0);
        for (const Tick &t : ticks(ax, 90))
            if (ax.grid) g.line(ax.map(t.v), y0, ax.map(t.v), y1, t.major ? GRID : "#f2f2f2", 1);
        for (const Tick &t : ticks(ay, 55))
            if (ay.grid) g.line(x0, ay.map(t.v), x1, ay.map(t.v), t.major ? GRID : "#f2f2f2", 1);
        if (zero_line && !ay.log && ay.lo < 0 && ay.hi > 0)
            g.line(x0, ay.map(0), x1, ay.map(0), "#999999", 1.2);
        g.s += "<g clip-path=\"url(#" + clip + ")\">\n";
    }
    // Closes the data group; frame, ticks, tick labels and axis labels on top.
    void over(Svg &g, const std::string &xlabel, const std::string &ylabel, bool empty,
              bool xtick_labels = true) const
    {
        g.s += "</g>\n";
        if (empty)
            g.text((x0 + x1) / 2, (y0 + y1) / 2 + 8, "no data", 22, "middle", "#999999");
        g.rect(x0, y0, x1 - x0, y1 - y0, "none", fmt(" stroke=\"%s\" stroke-width=\"1\"", FRAME));
        if (xtick_labels)
            for (const Tick &t : ticks(ax, 90)) {
                double x = ax.map(t.v);
                g.line(x, y1, x, y1 + (t.major ? 5 : 3), FRAME, 1);
                if (!t.label.empty()) g.text(x, y1 + 19, t.label, 12);
            }
        double wmax = 0;
        for (const Tick &t : ticks(ay, 55)) {
            double y = ay.map(t.v);
            g.line(x0 - (t.major ? 5 : 3), y, x0, y, FRAME, 1);
            if (!t.label.empty()) g.text(x0 - 8, y + 4, t.label, 12, "end");
            wmax = std::max(wmax, text_w(t.label, 12));
        }
        if (!xlabel.empty()) g.text((x0 + x1) / 2, y1 + 42, xlabel, 14, "middle", INK, " class=\"axis-label x\"");
        if (!ylabel.empty()) {
            double x = x0 - wmax - 20;
            g.text(x, (y0 + y1) / 2, ylabel, 14, "middle", INK,
                   fmt(" class=\"axis-label y\" transform=\"rotate(-90 %.1f %.1f)\"", x, (y0 + y1) / 2));
        }
    }
};

// A legend entry: kind 'o' dot, 'r' ring, '-' line, '=' dashed line, 'b' bar, '>' arrow of `len` px.
struct Item { char kind; const char *col; std::string label; double len; };

// Legend entries in centred rows within [l, r] starting at y; returns the height used.
double legend(Svg &g, const std::vector<Item> &items, double l, double r, double y)
{
    if (items.empty()) return 0;
    auto width = [](const Item &it) { return (it.kind == '>' ? it.len : 22) + 7 + text_w(it.label, 13); };
    size_t i = 0;
    double row = 0;
    while (i < items.size()) {
        size_t j = i;
        double w = 0;
        while (j < items.size() && (j == i || w + 28 + width(items[j]) <= r - l)) w += (j > i ? 28 : 0) + width(items[j]), j++;
        double x = (l + r - w) / 2, cy = y + row * 22 + 8;
        for (; i < j; i++) {
            const Item &it = items[i];
            double sw = it.kind == '>' ? it.len : 22;
            if (it.kind == 'o') g.s += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4.5\" fill=\"%s\"/>\n", x + 11, cy, it.col);
            if (it.kind == 'r')
                g.s += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"6\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"/>\n", x + 11, cy, it.col);
            if (it.kind == '-' || it.kind == '=')
                g.line(x, cy, x + 22, cy, it.col, 2.5, it.kind == '=' ? " stroke-dasharray=\"6 4\"" : "");
            if (it.kind == 'b') g.rect(x + 4, cy - 6, 14, 12, it.col);
            if (it.kind == '>') {
                g.s += fmt("<g stroke=\"%s\" fill=\"%s\" stroke-width=\"1.6\">\n", it.col, it.col);
                g.s += arrow(x, cy, x + sw, cy);
                g.s += "</g>\n";
            }
            g.text(x + sw + 7, cy + 4.5, it.label, 13, "start");
            x += sw + 7 + text_w(it.label, 13) + 28;
        }
        row++;
    }
    return row * 22;
}

int fail(std::string *err, const std::string &msg)
{
    if (err) *err = msg;
    return -1;
}

int finish(const Out &to, Svg &g, std::string *err)
{
    g.s += "</svg>\n";
    if (to.text) {
        *to.text = g.s;
        return 0;
    }
    if (to.path.empty()) return fail(err, "plot: empty output path");
    char buf[1024];
    if (pmhost::write_atomic(to.path, g.s, buf, sizeof buf) != 0) return fail(err, buf);
    return 0;
}

// A 1-2-5 value near v.
double round125(double v)
{
    double mag = std::pow(10.0, std::floor(std::log10(v))), f = v / mag;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

bool vec_ok(const Vec &p) { return fin(p.x) && fin(p.y) && fin(p.dx) && fin(p.dy); }

double auto_scale(const std::vector<Vec> &v)
{
    std::vector<double> len;
    for (const Vec &p : v)
        if (vec_ok(p)) len.push_back(std::hypot(p.dx, p.dy));
    if (len.empty()) return 1.0;
    std::nth_element(len.begin(), len.begin() + len.size() / 2, len.end());
    double m = len[len.size() / 2];
    return m > 0 ? round125(2 * m) : 1.0;
}

std::string arcsec(double v) { return (v >= 10 || v == std::floor(v) ? fmt("%.0f", v) : fmt("%.2g", v)) + " arcsec"; }

// One vector panel: header (title left, n and RMS right), then dots and arrows.
void vector_panel(Svg &g, Panel &p, const std::vector<Vec> &v, double scale, const std::string &ptitle,
                  const std::string &xlabel, const std::string &ylabel)
{
    double ss = 0;
    size_t n = 0;
    for (const Vec &q : v)
        if (vec_ok(q)) ss += q.dx * q.dx + q.dy * q.dy, n++;
    if (!ptitle.empty()) g.text(p.x0, p.y0 - 9, ptitle, 15, "start", "#111111", " font-weight=\"bold\"");
    if (n) g.text(p.x1, p.y0 - 9, fmt("n = %zu,  rms = %.3g arcsec", n, std::sqrt(ss / (double)n)), 13, "end");
    p.under(g);
    for (int grp = 0; grp < 8; grp++) {
        std::string dots, arrows;
        for (const Vec &q : v) {
            if (!vec_ok(q) || ((q.group % 8) + 8) % 8 != grp) continue;
            double x = p.ax.map(q.x), y = p.ay.map(q.y);
            dots += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"1.8\"/>\n", x, y);
            arrows += arrow(x, y, x + q.dx / scale * REF_PX, y - q.dy / scale * REF_PX);
        }
        if (dots.empty()) continue;
        g.s += fmt("<g fill=\"%s\" stroke=\"%s\" stroke-width=\"1.3\" stroke-linejoin=\"round\">\n", colour(grp), colour(grp));
        g.s += "<g stroke=\"none\">\n" + dots + "</g>\n" + arrows + "</g>\n";
    }
    p.over(g, xlabel, ylabel, n == 0);
}

// Shared by sky_vectors and sky_vectors_pair: panels side by side on common axes.
int vectors(const Out &path, const std::string &title, const std::string &xlabel,
            const std::string &ylabel, const std::vector<const std::vector<Vec> *> &sets,
            const std::vector<std::string> &ptitles, double scale,
            const std::vector<std::string> &names, std::string *err)
{
    if (!(scale > 0 && fin(scale))) scale = auto_scale(*sets[0]);
    double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
    int count[8] = {0};
    for (const auto *set : sets)
        for (const Vec &q : *set)
            if (vec_ok(q)) {
                mnx = std::min(mnx, q.x), mxx = std::max(mxx, q.x);
                mny = std::min(mny, q.y), mxy = std::max(mxy, q.y);
                if (set == sets[0]) count[((q.group % 8) + 8) % 8]++;
            }
    std::vector<Item> items;
    int ngroups = 0;
    for (int k = 0; k < 8; k++) ngroups += count[k] > 0;
    for (int k = 0; k < 8; k++)
        if (count[k] && (!names.empty() || ngroups > 1))
            items.push_back({'o', colour(k), (k < (int)names.size() ? names[k] : fmt("group %d", k)) + fmt(" (%d)", count[k]), 0});
    items.push_back({'>', INK, arcsec(scale), REF_PX});
    int np = (int)sets.size(), W = np == 1 ? 800 : 1320, H = 560;
    Svg g(W, H, title);
    double top = 50 + legend(g, items, 40, W - 40, 46) + 34;
    for (int i = 0; i < np; i++) {
        double l = i * (W - 30) / np + 90.0, r = (i + 1) * (W - 30) / np - 10.0;
        Panel p(g, l, top, r, H - 62);
        p.ax.angular = p.ay.angular = true;
        p.zero_line = false;
        set_range(p.ax, mnx, mxx, 0.06);
        set_range(p.ay, mny, mxy, 0.06);
        vector_panel(g, p, *sets[i], scale, ptitles[i], xlabel, i == 0 ? ylabel : "");
    }
    return finish(path, g, err);
}

} // namespace

int sky_vectors(const Out &path, const std::string &title, const std::string &xlabel,
                const std::string &ylabel, const std::vector<Vec> &v, double scale_arcsec,
                const std::vector<std::string> &group_names, std::string *err)
{
    return vectors(path, title, xlabel, ylabel, {&v}, {""}, scale_arcsec, group_names, err);
}

int sky_vectors_pair(const Out &path, const std::string &title, const std::string &xlabel,
                     const std::string &ylabel, const std::vector<Vec> &before,
                     const std::vector<Vec> &after, const std::string &before_title,
                     const std::string &after_title, double scale_arcsec,
                     const std::vector<std::string> &group_names, std::string *err)
{
    return vectors(path, title, xlabel, ylabel, {&before, &after}, {before_title, after_title}, scale_arcsec,
                   group_names, err);
}

namespace {

// A sequential colour scale (dark blue - teal - yellow), f in [0, 1].
std::string ramp(double f)
{
    static const double c[5][3] = {{38, 24, 110}, {42, 92, 160}, {33, 145, 140}, {94, 201, 98},
                                   {253, 231, 37}};
    f = std::min(1.0, std::max(0.0, fin(f) ? f : 0.0)) * 4;
    int i = std::min(3, (int)f);
    double t = f - i;
    return fmt("#%02x%02x%02x", (int)std::lround(c[i][0] + t * (c[i + 1][0] - c[i][0])),
               (int)std::lround(c[i][1] + t * (c[i + 1][1] - c[i][1])),
               (int)std::lround(c[i][2] + t * (c[i + 1][2] - c[i][2])));
}

} // namespace

int sky_scalar(const Out &path, const std::string &title, const std::string &xlabel,
               const std::string &ylabel, const std::vector<Cell> &cells, const std::string &unit,
               const std::vector<std::pair<double, double>> &marks, const std::string &marks_name,
               std::string *err, const std::vector<std::string> &mark_labels)
{
    double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY, vmax = 0;
    size_t n = 0;
    for (const Cell &c : cells)
        if (fin(c.x) && fin(c.y) && fin(c.w) && fin(c.h) && fin(c.v)) {
            mnx = std::min(mnx, c.x - c.w / 2), mxx = std::max(mxx, c.x + c.w / 2);
            mny = std::min(mny, c.y - c.h / 2), mxy = std::max(mxy, c.y + c.h / 2);
            vmax = std::max(vmax, c.v);
            n++;
        }
    const int W = 900, H = 560;
    Svg g(W, H, title);
    std::vector<Item> items;
    if (!marks.empty())
        items.push_back({mark_labels.empty() ? 'o' : 'r', INK, marks_name + fmt(" (%zu)", marks.size()), 0});
    double top = 50 + legend(g, items, 40, W - 140, 46) + 20;
    Panel p(g, 90, top, W - 150, H - 62);
    p.ax.angular = p.ay.angular = true;
    p.zero_line = false;
    if (!n)
        mnx = 0, mxx = 1, mny = 0, mxy = 1;
    set_range(p.ax, mnx, mxx, 0.0);
    set_range(p.ay, mny, mxy, 0.0);
    p.under(g);
    double vtop = vmax > 0 ? vmax : 1;
    for (const Cell &c : cells) {
        if (!(fin(c.x) && fin(c.y) && fin(c.w) && fin(c.h) && fin(c.v)))
            continue;
        double x0 = p.ax.map(c.x - c.w / 2), x1 = p.ax.map(c.x + c.w / 2);
        double y0 = p.ay.map(c.y + c.h / 2), y1 = p.ay.map(c.y - c.h / 2);
        g.rect(std::min(x0, x1), std::min(y0, y1), std::fabs(x1 - x0) + 0.6, std::fabs(y1 - y0) + 0.6,
               ramp(c.v / vtop).c_str());
    }
    for (size_t k = 0; k < marks.size(); k++) {
        const auto &m = marks[k];
        if (!fin(m.first) || !fin(m.second))
            continue;
        double x = p.ax.map(m.first), y = p.ay.map(m.second);
        if (mark_labels.empty()) {
            g.s += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.6\" fill=\"none\" stroke=\"%s\" "
                       "stroke-width=\"1.2\"/>\n", x, y, INK);
            continue;
        }
        // labelled marks: a bold ring on a white one, and its label beside it
        g.s += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"none\" stroke=\"#ffffff\" stroke-width=\"4.5\"/>\n"
                   "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"none\" stroke=\"#111111\" stroke-width=\"2\"/>\n",
                   x, y, x, y);
        if (k < mark_labels.size())
            g.text(x + 10, y - 6, mark_labels[k], 14, "start", "#111111", std::string(" font-weight=\"bold\"") + HALO);
    }
    p.over(g, xlabel, ylabel, n == 0);
    // the colour bar, 0 .. vmax
    double bx = W - 120, by0 = top, by1 = H - 62, steps = 40;
    for (int k = 0; k < steps; k++) {
        double f0 = k / steps, f1 = (k + 1) / steps;
        g.rect(bx, by1 - f1 * (by1 - by0), 18, (f1 - f0) * (by1 - by0) + 0.6, ramp((f0 + f1) / 2).c_str());
    }
    g.rect(bx, by0, 18, by1 - by0, "none", fmt(" stroke=\"%s\" stroke-width=\"1\"", FRAME));
    Axis a;
    a.p0 = by1;
    a.p1 = by0;
    set_range(a, 0, vtop, 0.0);
    a.lo = 0;
    a.hi = vtop;
    for (const Tick &t : ticks(a, 55)) {
        double y = a.map(t.v);
        g.line(bx + 18, y, bx + 23, y, FRAME, 1);
        if (!t.label.empty()) g.text(bx + 26, y + 4, t.label, 12, "start");
    }
    g.text(bx + 9, by0 - 8, unit, 13, "middle", INK, " class=\"axis-label bar\"");
    return finish(path, g, err);
}

namespace {

// The series of one xy panel, drawn into the open data group of p.
void xy_series(Svg &g, const Panel &p, const std::vector<Series> &s)
{
    for (size_t k = 0; k < s.size(); k++) {
        const Series &q = s[k];
        std::string d;
        bool pen = false;
        for (size_t i = 0; i < q.x.size(); i++) {
            if (!fin(q.x[i]) || !fin(q.y[i])) { pen = false; continue; }
            double x = p.ax.map(q.x[i]), y = p.ay.map(q.y[i]);
            if (q.line) d += fmt("%c%.1f %.1f", pen ? 'L' : 'M', x, y), pen = true;
            else d += fmt("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\"/>\n", x, y);
        }
        if (d.empty()) continue;
        if (q.line)
            g.s += fmt("<path fill=\"none\" stroke=\"%s\" stroke-width=\"2.2\" stroke-linejoin=\"round\" d=\"",
                       colour((int)k)) + d + "\"/>\n";
        else
            g.s += fmt("<g fill=\"%s\" fill-opacity=\"0.75\">\n", colour((int)k)) + d + "</g>\n";
    }
}

// Shared by xy and xy_pair: panels side by side on common axes, one legend (from the
// first set's names).
int xy_panels(const Out &path, const std::string &title, const std::string &xlabel,
              const std::string &ylabel, const std::vector<const std::vector<Series> *> &sets,
              const std::vector<std::string> &ptitles, std::string *err)
{
    double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
    std::vector<Item> items;
    for (const auto *set : sets)
        for (size_t k = 0; k < set->size(); k++) {
            const Series &q = (*set)[k];
            if (q.x.size() != q.y.size())
                return fail(err, fmt("%s: series %zu (\"%s\"): %zu x values but %zu y values", path.path.c_str(), k,
                                     q.name.c_str(), q.x.size(), q.y.size()));
            for (size_t i = 0; i < q.x.size(); i++)
                if (fin(q.x[i]) && fin(q.y[i])) {
                    mnx = std::min(mnx, q.x[i]), mxx = std::max(mxx, q.x[i]);
                    mny = std::min(mny, q.y[i]), mxy = std::max(mxy, q.y[i]);
                }
            if (set == sets[0] && !q.name.empty()) items.push_back({q.line ? '-' : 'o', colour((int)k), q.name, 0});
        }
    int np = (int)sets.size(), W = np == 1 ? 800 : 1320, H = 520;
    Svg g(W, H, title);
    double top = 50 + legend(g, items, 40, W - 40, 46) + (ptitles[0].empty() ? 12 : 34);
    for (int i = 0; i < np; i++) {
        double l = np == 1 ? 92 : i * (W - 30) / np + 92.0, r = np == 1 ? W - 28 : (i + 1) * (W - 30) / np - 10.0;
        Panel p(g, l, top, r, H - 62);
        set_range(p.ax, mnx, mxx, 0.04);
        set_range(p.ay, mny, mxy, 0.06);
        if (!ptitles[i].empty()) g.text(p.x0, p.y0 - 9, ptitles[i], 15, "start", "#111111", " font-weight=\"bold\"");
        p.under(g);
        xy_series(g, p, *sets[i]);
        p.over(g, xlabel, i == 0 ? ylabel : "", !(mnx <= mxx));
    }
    return finish(path, g, err);
}

} // namespace

int xy(const Out &path, const std::string &title, const std::string &xlabel,
       const std::string &ylabel, const std::vector<Series> &s, std::string *err)
{
    return xy_panels(path, title, xlabel, ylabel, {&s}, {""}, err);
}

int xy_pair(const Out &path, const std::string &title, const std::string &xlabel,
            const std::string &ylabel, const std::vector<Series> &before,
            const std::vector<Series> &after, const std::string &before_title,
            const std::string &after_title, std::string *err)
{
    return xy_panels(path, title, xlabel, ylabel, {&before, &after}, {before_title, after_title}, err);
}

int periodogram(const Out &path, const std::string &title, const std::vector<double> &freq,
                const std::vector<double> &power, double threshold,
                const std::string &threshold_label, double peak_freq, bool log_x, std::string *err)
{
    return periodogram(path, title, "power", freq, power, threshold, threshold_label, peak_freq, log_x, err);
}

int periodogram(const Out &path, const std::string &title, const std::string &ylabel,
                const std::vector<double> &freq, const std::vector<double> &power, double threshold,
                const std::string &threshold_label, double peak_freq, bool log_x, std::string *err)
{
    if (freq.size() != power.size())
        return fail(err, fmt("%s: %zu frequencies but %zu power values", path.path.c_str(), freq.size(), power.size()));
    auto ok = [&](size_t i) { return fin(freq[i]) && fin(power[i]) && (!log_x || freq[i] > 0); };
    double mnx = INFINITY, mxx = -INFINITY, mny = 0, mxy = -INFINITY;
    size_t ipk = freq.size();
    for (size_t i = 0; i < freq.size(); i++)
        if (ok(i)) {
            mnx = std::min(mnx, freq[i]), mxx = std::max(mxx, freq[i]);
            mny = std::min(mny, power[i]), mxy = std::max(mxy, power[i]);
            auto dist = [&](size_t j) { return log_x ? std::fabs(std::log(freq[j] / peak_freq)) : std::fabs(freq[j] - peak_freq); };
            if (fin(peak_freq) && (!log_x || peak_freq > 0) && (ipk == freq.size() || dist(i) < dist(ipk))) ipk = i;
        }
    bool empty = !(mnx <= mxx);
    if (!empty && fin(threshold)) mny = std::min(mny, threshold), mxy = std::max(mxy, threshold);
    const int W = 800, H = 500;
    Svg g(W, H, title);
    Panel p(g, 92, 58, W - 28, H - 62);
    p.ax.log = log_x;
    set_range(p.ax, mnx, mxx, 0.02);
    if (!empty) { p.ay.lo = mny; p.ay.hi = mxy > mny ? mxy + (mxy - mny) * 0.15 : mny + 1; }
    p.under(g);
    std::string d;
    bool pen = false;
    for (size_t i = 0; i < freq.size(); i++) {
        if (!ok(i)) { pen = false; continue; }
        d += fmt("%c%.1f %.1f", pen ? 'L' : 'M', p.ax.map(freq[i]), p.ay.map(power[i]));
        pen = true;
    }
    if (!d.empty())
        g.s += fmt("<path fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" stroke-linejoin=\"round\" d=\"", COLOUR[0]) + d + "\"/>\n";
    if (!empty && fin(threshold)) {
        double y = p.ay.map(threshold);
        g.line(p.x0, y, p.x1, y, COLOUR[1], 1.6, " stroke-dasharray=\"7 5\"");
        g.text(p.x1 - 8, y - 6, threshold_label, 13, "end", COLOUR[1], HALO);
    }
    g.s += "</g>\n<g>\n";  // the peak label may stand on the frame
    if (ipk < freq.size()) {
        double x = p.ax.map(freq[ipk]), y = p.ay.map(power[ipk]);
        g.s += fmt("<path d=\"M%.1f %.1fl-6 -10h12z\" fill=\"#111111\"/>\n", x, y - 3);
        const char *anchor = x < p.x0 + 50 ? "start" : x > p.x1 - 50 ? "end" : "middle";
        std::string lab = fmt(peak_freq >= 1 ? "G = %.1f" : "G = %.3g", freq[ipk]);
        g.text(x, std::max(y - 18, p.y0 + 14), lab, 14, anchor, "#111111", std::string(" font-weight=\"bold\"") + HALO);
    }
    p.over(g, "frequency (cycles per revolution)", ylabel, empty);
    return finish(path, g, err);
}

int steps(const Out &path, const std::string &title, const std::vector<std::string> &labels,
          const std::vector<double> &sigma, const std::vector<double> &cv_rms, std::string *err)
{
    size_t n = labels.size();
    if ((!sigma.empty() && sigma.size() != n) || (!cv_rms.empty() && cv_rms.size() != n))
        return fail(err, fmt("%s: %zu steps but %zu sigma and %zu CV RMS values", path.path.c_str(), n, sigma.size(),
                             cv_rms.size()));
    std::vector<const std::vector<double> *> ser;
    std::vector<Item> items;
    if (!sigma.empty()) ser.push_back(&sigma), items.push_back({'b', COLOUR[0], "sigma of the fit", 0});
    if (!cv_rms.empty()) ser.push_back(&cv_rms), items.push_back({'b', COLOUR[1], "cross-validated RMS", 0});
    double mx = -INFINITY, mn = 0, best = INFINITY, lw = 0;
    size_t ibest = n;
    for (size_t i = 0; i < n; i++) {
        lw = std::max(lw, text_w(labels[i], 12));
        for (const auto *v : ser)
            if (fin((*v)[i])) mx = std::max(mx, (*v)[i]), mn = std::min(mn, (*v)[i]);
        if (!cv_rms.empty() && fin(cv_rms[i]) && cv_rms[i] < best) best = cv_rms[i], ibest = i;
    }
    bool empty = !(mx >= mn), slant = n && lw > (800 - 120.0) / (double)n - 8;
    const int W = 800, H = 500 + (slant ? (int)(lw * 0.57) : 0);
    Svg g(W, H, title);
    double top = 50 + legend(g, items, 40, W - 40, 46) + 12;
    Panel p(g, 92, top, W - 28, slant ? H - 40 - lw * 0.57 : H - 50.0);
    p.ax.lo = 0, p.ax.hi = std::max<double>(1, (double)n), p.ax.grid = false;
    if (!empty) p.ay.lo = mn, p.ay.hi = mx > mn ? mx + (mx - mn) * 0.16 : mn + 1;
    p.under(g);
    int dec = std::max(mx, -mn) >= 100 ? 0 : std::max(mx, -mn) >= 10 ? 1 : 2;  // 3 digits for the largest
    double slot = (p.x1 - p.x0) / std::max<double>(1, (double)n), nk = std::max<double>(1, (double)ser.size());
    double bw = std::min(slot * 0.72 / nk, 64.0), pad = (slot - bw * nk) / 2;  // bars at most 64 px wide
    for (size_t i = 0; i < n; i++)
        for (size_t k = 0; k < ser.size(); k++) {
            double v = (*ser[k])[i];
            if (!fin(v)) continue;
            double x = p.x0 + slot * (double)i + pad + bw * (double)k, y0 = p.ay.map(0), y = p.ay.map(v);
            g.rect(x, std::min(y, y0), bw, std::fabs(y0 - y), COLOUR[ser[k] == &sigma ? 0 : 1]);
            if (bw >= 22) g.text(x + bw / 2, y - 5, fmt("%.*f", dec, v), 11);
            if (i == ibest && ser[k] == &cv_rms)
                g.text(x + bw / 2, y - (bw >= 22 ? 20 : 6), "best", 12, "middle", COLOUR[1], " font-weight=\"bold\"");
        }
    p.over(g, "", "arcsec", empty, false);
    for (size_t i = 0; i < n; i++) {
        double x = p.x0 + slot * ((double)i + 0.5), y = p.y1 + 18;
        std::string extra = i == ibest ? " font-weight=\"bold\"" : "";
        if (slant) g.text(x + 4, y - 4, labels[i], 12, "end", INK, extra + fmt(" transform=\"rotate(-35 %.1f %.1f)\"", x + 4, y - 4));
        else g.text(x, y, labels[i], 12, "middle", INK, extra);
    }
    return finish(path, g, err);
}

} // namespace pmplot

// ---------------------------------------------------------------------------
// C access and the demo (synthetic data, deterministic).

namespace {

struct Rng {
    unsigned long long s;
    double uniform()
    {
        s ^= s >> 12, s ^= s << 25, s ^= s >> 27;
        return (double)((s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
    }
    double gauss() { return std::sqrt(-2.0 * std::log(1.0 - uniform())) * std::cos(2.0 * M_PI * uniform()); }
};

int c_result(int rc, const std::string &msg, char *err, size_t errlen)
{
    if (rc) pmhost::set_err(err, errlen, msg);
    return rc;
}

const double DEG = M_PI / 180.0;

// A German equatorial mount at latitude 47 deg: index, collimation, non-perpendicularity,
// polar misalignment and tube flexure (Pal et al. on-sky forms), 1.5 arcsec noise; "after"
// keeps a small unmodelled worm-period term.
void demo_sky(std::vector<pmplot::Vec> &before, std::vector<pmplot::Vec> &after)
{
    Rng r{12345};
    const double lat = 47 * DEG;
    while (before.size() < 160) {
        double h = (r.uniform() * 220 - 110) * DEG, d = (r.uniform() * 113 - 25) * DEG;
        if (std::asin(std::sin(lat) * std::sin(d) + std::cos(lat) * std::cos(d) * std::cos(h)) < 15 * DEG) continue;
        double s = h > 0 ? 1 : -1;
        double dx = 25 * std::cos(d) + 18 * s + 6 * s * std::sin(d) - 14 * std::sin(h) * std::sin(d) +
                    9 * std::cos(h) * std::sin(d) + 10 * std::cos(lat) * std::sin(h);
        double dy = -12 + 14 * std::cos(h) + 9 * std::sin(h) +
                    10 * (std::cos(lat) * std::cos(h) * std::sin(d) - std::sin(lat) * std::cos(d));
        pmplot::Vec b = {h / DEG, d / DEG, dx + 1.5 * r.gauss(), dy + 1.5 * r.gauss(), h > 0};
        pmplot::Vec a = {h / DEG, d / DEG, 1.5 * r.gauss() + 2 * std::sin(3 * h), 1.5 * r.gauss(), h > 0};
        before.push_back(b), after.push_back(a);
    }
}

} // namespace

extern "C" int pmplot_xy_c(const char *path, const char *title, const char *xlabel, const char *ylabel,
                           const char *name, const double *x, const double *y, long n, int line,
                           char *err, size_t errlen)
{
    if (!path || (n > 0 && (!x || !y)) || n < 0)
        return c_result(-1, std::string(path ? path : "(null)") + ": bad arguments to pmplot_xy_c", err, errlen);
    pmplot::Series s = {name ? name : "", std::vector<double>(x, x + n), std::vector<double>(y, y + n), line != 0};
    std::string msg;
    int rc = pmplot::xy(path, title ? title : "", xlabel ? xlabel : "", ylabel ? ylabel : "", {s}, &msg);
    return c_result(rc, msg, err, errlen);
}

extern "C" int pmplot_demo(const char *dir, char *err, size_t errlen)
{
    if (!dir) return c_result(-1, "pmplot_demo: no directory", err, errlen);
    std::string d = std::string(dir) + "/", msg;
    std::vector<std::string> pier = {"pier east", "pier west"};
    std::vector<pmplot::Vec> before, after;
    demo_sky(before, after);
    int rc = pmplot::sky_vectors(d + "sky_vectors.svg", "Pointing residuals: baseline model (IH & ID only)",
                                 "hour angle (deg)", "declination (deg)", before, 0, pier, &msg);
    if (!rc)
        rc = pmplot::sky_vectors_pair(d + "sky_vectors_pair.svg", "Residuals before & after adding flexure + polar axis terms",
                                      "hour angle (deg)", "declination (deg)", before, after, "before: baseline",
                                      "after: +flexure +polar axis", 0, pier, &msg);
    Rng r{777};
    std::vector<pmplot::Series> s = {{"pier east", {}, {}, false}, {"pier west", {}, {}, false},
                                     {"model: 4\u2033 cot(el) \u2212 2\u2033", {}, {}, true}};
    for (int i = 0; i < 160; i++) {
        double el = 15 + 73 * r.uniform();
        pmplot::Series &q = s[i % 2];
        q.x.push_back(el), q.y.push_back(4 / std::tan(el * DEG) - 2 + (i % 2 ? 1.0 : -1.0) + 1.5 * r.gauss());
    }
    for (double el = 14; el <= 89; el += 0.5) s[2].x.push_back(el), s[2].y.push_back(4 / std::tan(el * DEG) - 2);
    if (!rc) rc = pmplot::xy(d + "xy.svg", "Elevation residual vs elevation: refraction & sag", "elevation (deg)",
                             "elevation residual (arcsec)", s, &msg);
    std::vector<double> f, p;
    for (int k = 1; k <= 600; k++) {
        double pk = 40 * std::exp(-0.5 * std::pow((k - 240) / 1.2, 2)) + 12 * std::exp(-0.5 * std::pow((k - 480) / 1.2, 2)) +
                    (k == 1 ? 15 : k == 2 ? 7 : 0);
        f.push_back(k), p.push_back(pk - std::log(1.0 - r.uniform()));
    }
    if (!rc) rc = pmplot::periodogram(d + "periodogram.svg", "Periodogram of HA residuals vs raw HA axis angle", f, p, 9.2,
                                      "false-alarm 1%", 240, true, &msg);
    if (!rc) rc = pmplot::periodogram(d + "periodogram_lin.svg", "Periodogram of HA residuals (linear) <worm & gear>",
                                      "power (arcsec\u00b2)", f, p, 9.2, "false-alarm 1%", 240, false, &msg);
    if (!rc) rc = pmplot::steps(d + "steps.svg", "Greedy model search: sigma & cross-validated RMS",
                                {"baseline", "+refraction", "+tube flexure", "+worm 240/rev", "+temperature", "+HA sin 2h"},
                                {38.2, 21.5, 12.4, 6.1, 4.9, 4.7}, {39.0, 22.3, 13.1, 6.6, 5.3, 5.5}, &msg);
    return c_result(rc, msg, err, errlen);
}

extern "C" int pmplot_demo_degenerate(const char *dir, char *err, size_t errlen)
{
    if (!dir) return c_result(-1, "pmplot_demo_degenerate: no directory", err, errlen);
    std::string d = std::string(dir) + "/", msg;
    const double nan = NAN, inf = INFINITY;
    std::vector<pmplot::Vec> none, v = {{nan, 10, 1, 1, 0}, {20, 30, 5, -3, 0}, {-40, 60, inf, 2, 1}, {10, 40, -4, 2, 1},
                                        {0, 0, 0, 0, 7}, {5, nan, 1, 1, -3}};
    std::vector<pmplot::Series> s = {{"data", {1, nan, 3, 4, inf}, {2, 5, nan, 1, 3}, false},
                                     {"line", {1, 2, nan, 4}, {1, 2, 3, nan}, true}, {"", {}, {}, true}};
    std::vector<double> f = {nan, -1, 0, 1, 2, 3, inf, 5}, p = {1, 2, 3, nan, 2, 7, 1, 0.5};
    int rc = pmplot::sky_vectors(d + "empty_sky.svg", "empty sky", "x", "y", none, 0, {}, &msg);
    if (!rc) rc = pmplot::sky_vectors_pair(d + "empty_pair.svg", "empty pair", "x", "y", none, none, "a", "b", nan, {}, &msg);
    if (!rc) rc = pmplot::xy(d + "empty_xy.svg", "empty xy", "x", "y", {}, &msg);
    if (!rc) rc = pmplot::periodogram(d + "empty_periodogram.svg", "empty periodogram", {}, {}, 1, "t", 3, true, &msg);
    if (!rc) rc = pmplot::steps(d + "empty_steps.svg", "empty steps", {}, {}, {}, &msg);
    if (!rc) rc = pmplot::sky_vectors(d + "nan_sky.svg", "sky with missing values", "x", "y", v, -1, {"only one name"}, &msg);
    if (!rc) rc = pmplot::xy(d + "nan_xy.svg", "xy with missing values", "x", "y", s, &msg);
    if (!rc) rc = pmplot::periodogram(d + "nan_periodogram.svg", "periodogram with missing values", f, p, nan, "t", nan, true, &msg);
    if (!rc) rc = pmplot::steps(d + "nan_steps.svg", "steps with missing values", {"a", "b", "c"}, {1, nan, 3}, {nan, nan, inf}, &msg);
    return c_result(rc, msg, err, errlen);
}
