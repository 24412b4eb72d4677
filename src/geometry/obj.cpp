#include "geometry/obj.h"

#include "core/error.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <string_view>
#include <vector>

namespace plume::geo {
namespace {

// Statements of the OBJ specification that carry nothing Plume renders.
const std::set<std::string_view> kIgnored = {
    "vt", "vp", "s", "usemtl", "mtllib", "l", "p", "mg", "lod", "usemap", "maplib", "shadow_obj",
    "trace_obj", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
    "scrv", "sp", "end", "con", "ctech", "stech", "bevel", "c_interp", "d_interp"};

class Parser {
 public:
  explicit Parser(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(name_ + ":" + std::to_string(line_) + ": " + what);
  }

  ObjMesh parse(std::istream& in) {
    std::string text;
    while (std::getline(in, text)) {
      ++line_;
      parseLine(text);
    }
    if (in.bad()) fail("read error");
    return std::move(out_);
  }

 private:
  static std::vector<std::string_view> split(std::string_view s) {
    std::vector<std::string_view> tokens;
    size_t i = 0;
    while (i < s.size()) {
      while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
      size_t j = i;
      while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
      if (j > i) tokens.push_back(s.substr(i, j - i));
      i = j;
    }
    return tokens;
  }

  float number(std::string_view tok) const {
    std::string_view s = tok;
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    float v = 0.0f;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec == std::errc::result_out_of_range) fail("coordinate '" + std::string(tok) + "' is out of float range");
    if (ec != std::errc() || end != s.data() + s.size()) fail("expected a number, got '" + std::string(tok) + "'");
    if (!std::isfinite(v)) fail("NaN or infinite coordinate '" + std::string(tok) + "'");
    return v;
  }

  glm::vec3 vector3(const std::vector<std::string_view>& t, size_t lo, size_t hi, const char* what) const {
    const size_t n = t.size() - 1;
    if (n < lo || n > hi)
      fail(std::string("`") + what + "` expects " + (lo == hi ? std::to_string(lo) : std::to_string(lo) + " to " + std::to_string(hi)) +
           " numbers, got " + std::to_string(n));
    glm::vec3 v;
    for (int a = 0; a < 3; ++a) v[a] = number(t[size_t(a) + 1]);
    for (size_t k = 4; k <= n; ++k) number(t[k]);  // w or a vertex colour: checked, unused
    return v;
  }

  // An OBJ index (1-based, or negative: relative to the `count` elements defined so far) to a
  // 0-based one.
  uint32_t index(std::string_view tok, size_t count, const char* what) const {
    long v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size()) fail(std::string("malformed ") + what + " index '" + std::string(tok) + "'");
    const long resolved = v > 0 ? v - 1 : long(count) + v;
    if (v == 0 || resolved < 0 || resolved >= long(count))
      fail(std::string(what) + " index " + std::to_string(v) + " out of range (" + std::to_string(count) + " " + what +
           (count == 1 ? "" : "s") + " defined so far)");
    return uint32_t(resolved);
  }

  void face(const std::vector<std::string_view>& t) {
    if (t.size() < 4) fail("a face needs at least 3 vertices, got " + std::to_string(t.size() - 1));
    std::vector<uint32_t> pos, nrm;
    int form = -1;  // 0: i, 1: i/t, 2: i//n, 3: i/t/n
    for (size_t k = 1; k < t.size(); ++k) {
      const std::string_view c = t[k];
      const size_t s1 = c.find('/');
      const size_t s2 = s1 == std::string_view::npos ? s1 : c.find('/', s1 + 1);
      if (s2 != std::string_view::npos && c.find('/', s2 + 1) != std::string_view::npos)
        fail("malformed face vertex '" + std::string(c) + "'");
      int f = 0;
      std::string_view p = c, tx, n;
      if (s1 != std::string_view::npos) {
        p = c.substr(0, s1);
        if (s2 == std::string_view::npos) {
          f = 1;
          tx = c.substr(s1 + 1);
        } else {
          tx = c.substr(s1 + 1, s2 - s1 - 1);
          n = c.substr(s2 + 1);
          f = tx.empty() ? 2 : 3;
          if (n.empty()) fail("malformed face vertex '" + std::string(c) + "' (empty normal index)");
        }
      }
      if (form != -1 && f != form) fail("face vertices mix the forms i, i/t, i//n, i/t/n");
      form = f;
      pos.push_back(index(p, out_.mesh.positions.size(), "position"));
      if (f == 1 || f == 3) index(tx, texcoords_, "texture coordinate");
      if (f >= 2) nrm.push_back(index(n, out_.mesh.normals.size(), "normal"));
    }
    ++out_.stats.faces;
    if (object_ == kNoObject) {
      object_ = uint32_t(out_.mesh.objects.size());
      out_.mesh.objects.push_back(objectName_);
    }
    for (size_t k = 1; k + 1 < pos.size(); ++k) {
      out_.mesh.triangles.push_back({pos[0], pos[k], pos[k + 1]});
      out_.mesh.triangleNormals.push_back(nrm.empty() ? glm::uvec3(kNoNormal) : glm::uvec3(nrm[0], nrm[k], nrm[k + 1]));
      out_.mesh.triangleObject.push_back(object_);
      if (doubleArea(out_.mesh, out_.mesh.triangles.size() - 1) == 0.0) {
        out_.mesh.triangles.pop_back();
        out_.mesh.triangleNormals.pop_back();
        out_.mesh.triangleObject.pop_back();
        ++out_.stats.degenerate;
      } else {
        ++out_.stats.triangles;
      }
    }
  }

  void parseLine(std::string_view text) {
    if (const size_t hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
    const std::vector<std::string_view> t = split(text);
    if (t.empty()) return;
    const std::string_view key = t[0];
    if (key == "v") {
      out_.mesh.positions.push_back(vector3(t, 3, 6, "v"));
    } else if (key == "vn") {
      const glm::vec3 n = vector3(t, 3, 3, "vn");
      const float len = glm::length(n);
      if (!(len > 0.0f) || !std::isfinite(len)) fail("`vn` of zero length");
      out_.mesh.normals.push_back(n / len);
    } else if (key == "vt") {
      ++texcoords_;
    } else if (key == "f") {
      face(t);
    } else if (key == "o" || key == "g") {
      std::string name;
      for (size_t k = 1; k < t.size(); ++k) {
        if (k > 1) name += ' ';
        name.append(t[k]);
      }
      objectName_ = name;
      object_ = kNoObject;
    } else if (!kIgnored.count(key)) {
      fail("unknown statement '" + std::string(key) + "'");
    }
  }

  static constexpr uint32_t kNoObject = 0xffffffffu;
  std::string name_;
  size_t line_ = 0;
  size_t texcoords_ = 0;
  std::string objectName_;
  uint32_t object_ = kNoObject;
  ObjMesh out_;
};

}  // namespace

ObjMesh parseObj(std::istream& in, const std::string& name) { return Parser(name).parse(in); }

ObjMesh loadObj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the OBJ file");
  return parseObj(in, path);
}

}  // namespace plume::geo
