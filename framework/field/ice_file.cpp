#include "framework/field/ice_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <unordered_set>

#include <pugixml.hpp>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"

namespace gem {

namespace {

// ---------------------------------------------------------------------------------------------
// Reading

// Turns pugixml's byte offsets into line:column for InputError. pugixml reports offsets only;
// users need the place in their editor's terms (1-based lines, columns in characters).
class SourceMap {
 public:
  SourceMap(std::string file, const std::string& content) : m_file(std::move(file)), m_content(content) {}

  InputError error(std::ptrdiff_t offset, const std::string& message) const {
    const auto [line, column] = lineColumn(offset);
    return InputError(m_file, line, column, message);
  }
  // Counted on from the last place asked for when this one is further on: the objects of a large
  // field are asked for in file order, so their places take one pass over the file, not one each.
  std::pair<int, int> lineColumn(std::ptrdiff_t offset) const {
    const auto end = static_cast<size_t>(std::clamp<std::ptrdiff_t>(offset, 0, std::ssize(m_content)));
    // A UTF-8 byte order mark is invisible in editors: do not count it as a column.
    const size_t start = m_content.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    if (end < m_counted.at) m_counted = Counted{};
    int line = m_counted.line, column = m_counted.column;
    for (size_t k = std::max(std::min(start, end), m_counted.at); k < end; ++k) {
      const auto c = static_cast<unsigned char>(m_content[k]);
      if (c == '\n') {
        ++line;
        column = 1;
      } else if ((c & 0xC0) != 0x80) {  // count UTF-8 continuation bytes as part of their character
        ++column;
      }
    }
    m_counted = Counted{std::max(end, m_counted.at), line, column};
    return {line, column};
  }
  // An element's offset_debug() points at its name; the reader's eye looks for the '<' before it.
  InputError error(pugi::xml_node node, const std::string& message) const { return error(offsetOf(node), message); }
  // "FILE:LINE:COLUMN" of an element, for a message made later (a body's polygon checked when the
  // world is built).
  std::string place(pugi::xml_node node) const {
    const auto [line, column] = lineColumn(offsetOf(node));
    return m_file + ":" + std::to_string(line) + ":" + std::to_string(column);
  }

 private:
  static std::ptrdiff_t offsetOf(pugi::xml_node node) {
    std::ptrdiff_t offset = node ? node.offset_debug() : 0;
    if (node.type() == pugi::node_element && offset > 0) --offset;
    return offset;
  }
  std::string m_file;
  const std::string& m_content;
  struct Counted {
    size_t at = 0;  // bytes counted so far, and the line and column they reach
    int line = 1, column = 1;
  };
  mutable Counted m_counted;
};

// XML whitespace is exactly these four characters (XML 1.0, production S); no locale involved.
bool isXmlSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

std::string_view trim(std::string_view s) {
  const auto isSpace = isXmlSpace;
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

// Parses a whole token as a number; the message says whether it was not a number or not finite.
// A leading '+' is accepted as strtod would (from_chars alone refuses it).
// `what` describes the value for a message; it is a callable so the message is built only on
// error (building it per coordinate made reading a large file several times slower).
template <class Describe>
Real parseReal(std::string_view token, const SourceMap& src, std::ptrdiff_t offset, Describe&& what) {
  std::string_view t = trim(token);
  if (t.starts_with('+')) t.remove_prefix(1);
  // Parsed straight into Real: a float build gets the correctly rounded float, not a double
  // rounded twice.
  Real value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec == std::errc::result_out_of_range && end == t.data() + t.size())
    throw src.error(offset, what() + " " + quoted(trim(token)) + " is out of range for a " + (sizeof(Real) == 8 ? "double" : "float"));
  if (t.empty() || ec != std::errc() || end != t.data() + t.size())
    throw src.error(offset, what() + " " + quoted(trim(token)) + " is not a number");
  if (!std::isfinite(value)) throw src.error(offset, what() + " " + quoted(trim(token)) + " is not a finite number");
  return value;
}

std::int64_t parseIndex(pugi::xml_node node, const char* attribute, const SourceMap& src, const std::string& what) {
  const pugi::xml_attribute a = node.attribute(attribute);
  if (!a) throw src.error(node, what + " has no " + attribute + " attribute");
  const std::string_view t = trim(a.value());
  std::int64_t value = -1;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size() || value < 0)
    throw src.error(node, what + ": " + attribute + "=" + quoted(a.value()) + " is not a non-negative integer");
  return value;
}

BodyKind parseKind(pugi::xml_node object, const SourceMap& src, const std::string& what) {
  const std::string_view k = trim(object.attribute("kind").value());
  if (k == "floe") return BodyKind::Floe;
  if (k == "vessel") return BodyKind::Vessel;
  if (k == "wall") return BodyKind::Wall;
  throw src.error(object, what + ": kind=" + quoted(k) + " is not one of floe, vessel, wall");
}

// "x0 y0 x1 y1 ...": whitespace separates values (commas too, which some writers use).
std::vector<Vec2> parseCoordinates(pugi::xml_node element, const SourceMap& src, const std::string& what) {
  const pugi::xml_text text = element.text();
  const std::string_view value = text ? text.get() : "";
  // Offsets point at the offending value itself, so long multi-line coordinate lists stay usable.
  const std::ptrdiff_t base = text ? text.data().offset_debug() : element.offset_debug() - 1;
  std::vector<Real> numbers;
  size_t k = 0;
  const auto isSeparator = [](char c) { return c == ',' || isXmlSpace(c); };
  while (k < value.size()) {
    while (k < value.size() && isSeparator(value[k])) ++k;
    if (k == value.size()) break;
    const size_t start = k;
    while (k < value.size() && !isSeparator(value[k])) ++k;
    const auto describe = [&] { return what + ": coordinate value " + std::to_string(numbers.size() + 1); };
    const std::ptrdiff_t offset = base + static_cast<std::ptrdiff_t>(start);
    numbers.push_back(parseReal(value.substr(start, k - start), src, offset, describe));
  }
  if (numbers.size() % 2 != 0)
    throw src.error(element, what + ": odd number of coordinate values (" + std::to_string(numbers.size()) + "); expected x y pairs");
  std::vector<Vec2> points(numbers.size() / 2);
  for (size_t p = 0; p < points.size(); ++p) points[p] = {numbers[2 * p], numbers[2 * p + 1]};
  // A ring closed by repeating its first vertex is the same polygon; the repeat would be a
  // zero-length edge that convexity checks refuse.
  if (points.size() > 3 && points.front().x == points.back().x && points.front().y == points.back().y) points.pop_back();
  if (points.size() < 3 || points.size() > static_cast<size_t>(kMaxVertices))
    throw src.error(element,
                    what + ": " + std::to_string(points.size()) + " vertices; a polygon needs 3 to " + std::to_string(kMaxVertices));
  return points;
}

IceObject parseObject(pugi::xml_node node, bool firstFrame, const SourceMap& src) {
  IceObject object;
  object.index = parseIndex(node, "index", src, "object");
  if (firstFrame) object.place = src.place(node);
  const std::string what = "object " + std::to_string(object.index);
  // An element GEM reads, given twice, is a hand edit whose intent is unknown: the first was taken
  // silently (two <coordinates>, a second <thickness>). Other elements stay a reader's to ignore.
  for (const char* name : {"coordinates", "velocity", "thickness", "removed"}) {
    const pugi::xml_node first = node.child(name);
    if (const pugi::xml_node second = first ? first.next_sibling(name) : pugi::xml_node())
      throw src.error(second, what + ": a second <" + name + ">; an object gives each element once");
  }
  if (node.attribute("kind")) {
    object.kind = parseKind(node, src, what);
    object.hasKind = true;
  }
  if (node.child("removed")) {
    if (firstFrame) throw src.error(node.child("removed"), what + ": <removed/> cannot appear in frame 0");
    object.removed = true;
  }
  if (const pugi::xml_node c = node.child("coordinates")) {
    object.coordinates = parseCoordinates(c, src, what);
    object.hasCoordinates = true;
  } else if (firstFrame) {
    throw src.error(node, what + " in frame 0 has no <coordinates>");
  }
  if (const pugi::xml_node v = node.child("velocity")) {
    // Its attributes are x, y and a: another (vx="1", a typo) left the velocity zero, silently.
    for (const pugi::xml_attribute a : v.attributes())
      if (std::string_view(a.name()) != "x" && std::string_view(a.name()) != "y" && std::string_view(a.name()) != "a")
        throw src.error(v, what + ": velocity " + a.name() + "=" + quoted(a.value()) + ": the velocity's attributes are x, y and a");
    // A missing component reads as zero: the thesis files always write all three, others may not.
    const auto component = [&](const char* name) {
      const pugi::xml_attribute a = v.attribute(name);
      const auto describe = [&] { return what + ": velocity " + name; };
      return a ? parseReal(a.value(), src, v.offset_debug() - 1, describe) : Real(0);
    };
    object.velocity = {component("x"), component("y")};
    object.angularVelocity = component("a");
    object.hasVelocity = true;
  }
  if (const pugi::xml_node t = node.child("thickness")) {
    const pugi::xml_text text = t.text();
    const std::ptrdiff_t offset = text ? text.data().offset_debug() : t.offset_debug() - 1;
    object.thickness = parseReal(text ? text.get() : "", src, offset, [&] { return what + ": thickness"; });
    if (!(object.thickness > 0)) throw src.error(offset, what + ": thickness " + quoted(trim(text.get())) + " must be positive");
    object.hasThickness = true;
  } else if (firstFrame) {
    throw src.error(node, what + " in frame 0 has no <thickness>");
  }
  return object;
}

// One document: the root element, with only comments and processing instructions around it (and
// an XML declaration and a doctype before it). Anything else outside the root (a second root
// element, a second document's declaration, text, CDATA) is refused where it starts: it was taken
// silently, the first root read and the rest dropped.
void requireOneDocument(const pugi::xml_document& doc, pugi::xml_node root, const SourceMap& src, const std::string& content) {
  bool afterRoot = false;
  for (const pugi::xml_node n : doc.children()) {
    // Where the node starts: pugixml points into it (an element's name, a text's first byte).
    std::ptrdiff_t at = std::max<std::ptrdiff_t>(n.offset_debug(), 0);
    if (n.type() == pugi::node_pcdata) {
      while (at < std::ssize(content) && isXmlSpace(content[static_cast<size_t>(at)])) ++at;
    } else {
      while (at > 0 && content[static_cast<size_t>(at)] != '<') --at;
    }
    const std::string where = afterRoot ? "after the root element </" + std::string(root.name()) + ">"
                                        : "before the root element <" + std::string(root.name()) + ">";
    switch (n.type()) {
      case pugi::node_element:
        if (n == root) {
          afterRoot = true;
          break;
        }
        throw src.error(at, "a second root element <" + std::string(n.name()) + "> " + where +
                                ": a .ice file holds one <iceFloeSim> (two files joined together?)");
      case pugi::node_declaration:
        if (n == doc.first_child()) break;
        throw src.error(at,
                        "an XML declaration <?xml ...?> " + where + ": it may only open the file (a second document joined to the first?)");
      case pugi::node_doctype:
        if (!afterRoot) break;
        throw src.error(at, "a <!DOCTYPE> " + where + ": it may only come before the root");
      case pugi::node_pcdata:
      case pugi::node_cdata: {
        const std::string_view text = trim(n.value());
        throw src.error(at, std::string(n.type() == pugi::node_cdata ? "a CDATA section " : "text ") + quoted(text.substr(0, 40)) +
                                (text.size() > 40 ? "..." : "") + " " + where +
                                ": only comments and processing instructions may stand outside the root element");
      }
      default:  // comments and processing instructions may stand anywhere (XML 1.0, Misc)
        break;
    }
  }
}

std::string readWholeFile(const std::filesystem::path& path) {
  requireRegularFile(path, ".ice file");
  requireFitsInMemory(path, 4);  // the text, and pugixml's tree of it
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), 0, 0, std::string("cannot open: ") + std::strerror(errno ? errno : ENOENT));
  // One read of the whole file where its size is known (the character-by-character copy is
  // several times slower on large files); a pipe or other unsized input falls back to that copy.
  std::string content;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
  if (size >= 0) {
    in.seekg(0, std::ios::beg);
    content.resize(static_cast<size_t>(size));
    in.read(content.data(), size);
    if (in.gcount() != size) in.setstate(std::ios::badbit);
  } else {
    in.clear();
    content.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  if (in.bad()) throw InputError(path.string(), 0, 0, std::string("cannot read: ") + std::strerror(errno));
  return content;
}

// Parses the file; frameZeroOnly skips converting later frames (a field read from a long run's
// output needs only its first frame), though the XML is still checked as a whole.
std::vector<IceFrame> parseIceFile(const std::filesystem::path& path, bool frameZeroOnly) {
  const std::string content = readWholeFile(path);
  const SourceMap src(path.string(), content);

  pugi::xml_document doc;
  // No end-of-line normalisation: it would shift text offsets of Windows files and so the columns.
  // pugixml takes a second root element, and drops text, a doctype or an XML declaration outside
  // the root without a word: the fragment, declaration and doctype flags keep them as nodes, so
  // that requireOneDocument below can refuse them.
  const unsigned flags = (pugi::parse_default & ~pugi::parse_eol) | pugi::parse_fragment | pugi::parse_declaration | pugi::parse_doctype;
  const pugi::xml_parse_result parsed = doc.load_buffer(content.data(), content.size(), flags);
  if (!parsed) throw src.error(parsed.offset, std::string("malformed XML: ") + parsed.description());

  const pugi::xml_node root = doc.document_element();  // the first element
  std::string rootName = root ? root.name() : "";
  std::string lower = rootName;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (lower != "icefloesim")
    throw src.error(root, "expected the root element <iceFloeSim>, found " + (root ? "<" + rootName + ">" : std::string("no element")));
  requireOneDocument(doc, root, src, content);

  std::vector<IceFrame> frames;
  std::unordered_set<std::int64_t> seenFrames;
  bool haveFrameZero = false;
  for (const pugi::xml_node f : root.children("frame")) {
    const std::int64_t index = parseIndex(f, "index", src, "frame");
    if (index > std::numeric_limits<int>::max()) throw src.error(f, "frame index " + std::to_string(index) + " is too large");
    if (!seenFrames.insert(index).second) throw src.error(f, "duplicate frame index " + std::to_string(index));
    const bool firstFrame = index == 0;
    haveFrameZero = haveFrameZero || firstFrame;
    if (frameZeroOnly && !firstFrame) continue;

    IceFrame frame;
    frame.index = static_cast<int>(index);
    if (const pugi::xml_attribute t = f.attribute("time")) {
      const auto describe = [&] { return "frame " + std::to_string(index) + ": time"; };
      frame.time = parseReal(t.value(), src, f.offset_debug() - 1, describe);
      frame.hasTime = true;
    }
    std::unordered_set<std::int64_t> ids;  // the index is the object's identity across frames
    for (const pugi::xml_node o : f.children("object")) {
      IceObject object = parseObject(o, firstFrame, src);
      if (!ids.insert(object.index).second)
        throw src.error(o, "duplicate object index " + std::to_string(object.index) + " in frame " + std::to_string(index));
      frame.objects.push_back(std::move(object));
    }
    frames.push_back(std::move(frame));
  }

  if (const pugi::xml_attribute n = root.attribute("numFrames")) {
    const std::string_view t = trim(n.value());
    long long declared = -1;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), declared);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size() || declared < 0)
      throw src.error(root, "numFrames=" + quoted(n.value()) + " is not a non-negative integer");
    if (declared != std::ssize(seenFrames))
      throw src.error(root,
                      "numFrames=" + std::to_string(declared) + " but the file holds " + std::to_string(seenFrames.size()) + " frames");
  }
  if (!haveFrameZero) throw src.error(root, "no frame with index 0 (the initial frame holding every object)");
  return frames;
}

}  // namespace

std::vector<IceFrame> readIceFile(const std::filesystem::path& path) { return parseIceFile(path, false); }

std::vector<BodySpec> readIceInitialBodies(const std::filesystem::path& path) {
  const std::vector<IceFrame> frames = parseIceFile(path, true);
  const auto first = std::find_if(frames.begin(), frames.end(), [](const IceFrame& f) { return f.index == 0; });
  std::vector<BodySpec> bodies;
  bodies.reserve(first->objects.size());
  for (const IceObject& o : first->objects) {
    BodySpec spec;
    spec.kind = o.kind;
    spec.vertices = o.coordinates;
    spec.thickness = o.thickness;
    spec.velocity = o.velocity;
    spec.angularVelocity = o.angularVelocity;
    spec.id = o.index;
    spec.origin = o.place + ": object " + std::to_string(o.index);
    bodies.push_back(std::move(spec));
  }
  return bodies;
}

}  // namespace gem
