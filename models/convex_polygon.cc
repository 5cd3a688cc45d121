#include "models/convex_polygon.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {
namespace {

// Twice the signed area of triangle (a, b, c): > 0 when counter-clockwise.
double Orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return Cross2(b - a, c - a);
}

// True when p lies in the closed triangle (a, b, c) given counter-clockwise.
bool InTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  return Orient(a, b, p) >= 0.0 && Orient(b, c, p) >= 0.0 && Orient(c, a, p) >= 0.0;
}

// Ear clipping: triangles as index triples into `ring`; empty when no ear can be found.
std::vector<std::vector<int>> Triangulate(const Ring2& ring) {
  std::vector<int> left(ring.size());
  for (size_t i = 0; i < ring.size(); ++i)
    left[i] = static_cast<int>(i);
  std::vector<std::vector<int>> triangles;
  while (left.size() > 3) {
    const size_t n = left.size();
    bool clipped = false;
    for (size_t i = 0; i < n && !clipped; ++i) {
      const int p = left[(i + n - 1) % n], v = left[i], q = left[(i + 1) % n];
      if (Orient(ring[p], ring[v], ring[q]) <= 0.0) continue;  // reflex or flat
      bool empty = true;
      for (int w : left) {
        if (w == p || w == v || w == q) continue;
        if (InTriangle(ring[w], ring[p], ring[v], ring[q])) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      triangles.push_back({p, v, q});
      left.erase(left.begin() + static_cast<long>(i));
      clipped = true;
    }
    if (!clipped) return {};
  }
  if (Orient(ring[left[0]], ring[left[1]], ring[left[2]]) > 0.0) triangles.push_back(left);
  return triangles;
}

// Merges piece b into piece a across their shared edge (u, v) in a and (v, u) in b; empty when
// they share no edge.
std::vector<int> MergeAcrossSharedEdge(const std::vector<int>& a, const std::vector<int>& b) {
  for (size_t i = 0; i < a.size(); ++i) {
    const int u = a[i], v = a[(i + 1) % a.size()];
    for (size_t j = 0; j < b.size(); ++j) {
      if (b[j] != v || b[(j + 1) % b.size()] != u) continue;
      std::vector<int> merged;
      for (size_t k = 0; k <= i; ++k)
        merged.push_back(a[k]);  // ... u
      // b from u onwards, around to just before v.
      for (size_t k = 2; k < b.size(); ++k)
        merged.push_back(b[(j + k) % b.size()]);
      for (size_t k = i + 1; k < a.size(); ++k)
        merged.push_back(a[k]);  // v ...
      return merged;
    }
  }
  return {};
}

Ring2 RingOf(const Ring2& points, const std::vector<int>& ids) {
  Ring2 ring;
  for (int id : ids)
    ring.push_back(points[id]);
  return ring;
}

}  // namespace

Line2 Line2::Through(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = (b - a).normalized();
  Line2 line;
  line.normal = {-d.y(), d.x()};
  line.offset = line.normal.dot(a);
  return line;
}

double RingSignedArea(const Ring2& ring) {
  double twice = 0.0;
  for (size_t i = 0; i < ring.size(); ++i)
    twice += Cross2(ring[i], ring[(i + 1) % ring.size()]);
  return 0.5 * twice;
}

Eigen::Vector2d RingCentroid(const Ring2& ring) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : ring)
    mean += p;
  mean /= std::max<size_t>(ring.size(), 1);
  // Relative to the vertex mean for accuracy; falls back to it for rings without area.
  double twice = 0.0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d a = ring[i] - mean, b = ring[(i + 1) % ring.size()] - mean;
    const double c = Cross2(a, b);
    twice += c;
    sum += c * (a + b);
  }
  return std::abs(twice) > 1e-15 ? Eigen::Vector2d(mean + sum / (3.0 * twice)) : mean;
}

bool RingContains(const Ring2& ring, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

bool ConvexInteriorsDisjoint(const Ring2& a, const Ring2& b, double tolerance) {
  for (const Ring2* ring : {&a, &b}) {
    for (size_t i = 0; i < ring->size(); ++i) {
      const Eigen::Vector2d d = (*ring)[(i + 1) % ring->size()] - (*ring)[i];
      if (d.norm() == 0.0) continue;
      const Eigen::Vector2d n = Eigen::Vector2d(d.y(), -d.x()).normalized();
      double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo;
      double b_lo = a_lo, b_hi = -a_lo;
      for (const Eigen::Vector2d& p : a)
        a_lo = std::min(a_lo, n.dot(p)), a_hi = std::max(a_hi, n.dot(p));
      for (const Eigen::Vector2d& p : b)
        b_lo = std::min(b_lo, n.dot(p)), b_hi = std::max(b_hi, n.dot(p));
      if (a_hi <= b_lo + tolerance || b_hi <= a_lo + tolerance) return true;
    }
  }
  return false;
}

double DistanceToSegment(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s.a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (s.a + t * d - p).norm();
}

bool ConvexContains(const Ring2& convex, const Eigen::Vector2d& p, double tolerance) {
  for (size_t i = 0; i < convex.size(); ++i) {
    const Eigen::Vector2d& a = convex[i];
    const Eigen::Vector2d& b = convex[(i + 1) % convex.size()];
    const double length = (b - a).norm();
    if (length > 0.0 && Cross2(b - a, p - a) < -tolerance * length) return false;
  }
  return !convex.empty();
}

double DistanceToConvex(const Ring2& convex, const Eigen::Vector2d& p) {
  if (ConvexContains(convex, p)) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < convex.size(); ++i) {
    best = std::min(best, DistanceToSegment(p, {convex[i], convex[(i + 1) % convex.size()]}));
  }
  return best;
}

bool SplitConvex(const Ring2& convex, const Line2& line, double min_area, Ring2* positive,
                 Ring2* negative) {
  const size_t n = convex.size();
  std::vector<double> s(n);
  bool any_pos = false, any_neg = false;
  for (size_t i = 0; i < n; ++i) {
    s[i] = line.SignedDistance(convex[i]);
    if (std::abs(s[i]) < 1e-12) s[i] = 0.0;
    any_pos |= s[i] > 0.0;
    any_neg |= s[i] < 0.0;
  }
  if (!any_pos || !any_neg) return false;
  Ring2 pos, neg;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    if (s[i] >= 0.0) pos.push_back(convex[i]);
    if (s[i] <= 0.0) neg.push_back(convex[i]);
    if ((s[i] > 0.0 && s[j] < 0.0) || (s[i] < 0.0 && s[j] > 0.0)) {
      const Eigen::Vector2d x = convex[i] + s[i] / (s[i] - s[j]) * (convex[j] - convex[i]);
      pos.push_back(x);
      neg.push_back(x);
    }
  }
  if (RingSignedArea(pos) < min_area || RingSignedArea(neg) < min_area) return false;
  *positive = std::move(pos);
  *negative = std::move(neg);
  return true;
}

void ConvexHull(Ring2* points, Ring2* hull) {
  std::sort(points->begin(), points->end(), LexicographicLess);
  Ring2& h = *hull;
  h.resize(2 * points->size());
  size_t k = 0;
  for (size_t pass = 0; pass < 2; ++pass) {
    const size_t start = k;
    for (const Eigen::Vector2d& p : *points) {
      while (k >= start + 2 && Cross2(h[k - 1] - h[k - 2], p - h[k - 2]) <= 0.0)
        --k;
      h[k++] = p;
    }
    --k;  // the last point starts the other chain
    std::reverse(points->begin(), points->end());
  }
  h.resize(std::max<size_t>(k, 1));
}

Ring2 ClipConvex(const Ring2& convex, const Line2& line) {
  Ring2 out;
  const size_t n = convex.size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d &p = convex[i], &q = convex[(i + 1) % n];
    const double sp = line.SignedDistance(p), sq = line.SignedDistance(q);
    if (sp >= 0.0) out.push_back(p);
    if ((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0))
      out.push_back(p + sp / (sp - sq) * (q - p));
  }
  return out;
}

bool ClipSegmentToConvex(const Ring2& convex, const Segment2& s, double* t0, double* t1) {
  double lo = 0.0, hi = 1.0;
  const Eigen::Vector2d d = s.b - s.a;
  for (size_t i = 0; i < convex.size(); ++i) {
    const Eigen::Vector2d& a = convex[i];
    const Eigen::Vector2d e = convex[(i + 1) % convex.size()] - a;
    const double f0 = Cross2(e, s.a - a);  // inside: f0 + t f1 >= 0
    const double f1 = Cross2(e, d);
    if (f1 == 0.0) {
      if (f0 < 0.0) return false;
      continue;
    }
    const double t = -f0 / f1;
    if (f1 > 0.0) {
      lo = std::max(lo, t);
    } else {
      hi = std::min(hi, t);
    }
    if (lo > hi) return false;
  }
  *t0 = lo;
  *t1 = hi;
  return !convex.empty();
}

bool IsConvexRing(const Ring2& ring, double tolerance) {
  if (ring.size() < 3) return false;
  for (size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % ring.size()];
    const Eigen::Vector2d& c = ring[(i + 2) % ring.size()];
    if (Cross2(b - a, c - b) < -tolerance * std::max(1.0, (b - a).norm() * (c - b).norm())) {
      return false;
    }
  }
  return RingSignedArea(ring) > 0.0;
}

std::vector<Ring2> ConvexPieces(const Ring2& ring) {
  if (ring.size() < 3) return {};
  if (IsConvexRing(ring)) return {ring};
  std::vector<std::vector<int>> pieces = Triangulate(ring);
  if (pieces.empty()) return {};
  bool merged_any = true;
  while (merged_any) {
    merged_any = false;
    for (size_t i = 0; i < pieces.size() && !merged_any; ++i) {
      for (size_t j = i + 1; j < pieces.size() && !merged_any; ++j) {
        std::vector<int> merged = MergeAcrossSharedEdge(pieces[i], pieces[j]);
        if (merged.empty() || !IsConvexRing(RingOf(ring, merged))) continue;
        pieces[i] = std::move(merged);
        pieces.erase(pieces.begin() + static_cast<long>(j));
        merged_any = true;
      }
    }
  }
  std::vector<Ring2> out;
  for (const std::vector<int>& piece : pieces)
    out.push_back(RingOf(ring, piece));
  return out;
}

Ring2 SimplifyRing(const Ring2& ring, double tolerance) {
  Ring2 r = ring;
  bool changed = true;
  while (changed && r.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < r.size() && !changed; ++i) {
      const Eigen::Vector2d& a = r[(i + r.size() - 1) % r.size()];
      const Eigen::Vector2d& b = r[i];
      const Eigen::Vector2d& c = r[(i + 1) % r.size()];
      const double longest = std::max({(b - a).norm(), (c - b).norm(), (c - a).norm()});
      // b is a duplicate, a straight-through vertex or the tip of a spike: its triangle has no
      // height above its longest side.
      if ((b - a).norm() <= tolerance || std::abs(Cross2(b - a, c - a)) <= tolerance * longest) {
        r.erase(r.begin() + static_cast<long>(i));
        changed = true;
      }
    }
  }
  return r.size() >= 3 ? r : Ring2{};
}

}  // namespace linetrack
