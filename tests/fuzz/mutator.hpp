// A deterministic, seeded mutator for the loader fuzz tests (tests/fuzz/test_fuzz_loaders.cpp).
//
// Not coverage-guided: the loaders are small parsers of line-oriented text (Moving AI, map_server
// YAML, config YAML, JSON) or of a few header lines plus a tree layout (OctoMap), and what breaks
// such parsers is structural: a byte at a boundary, a number out of range, a field cut in half,
// two files spliced together, a key repeated, nesting deeper than a recursive parser's stack.
// Every mutation below aims at one of those. Each input is made from a fresh generator seeded
// from (base seed, loader, iteration), so any single input is reproduced without running the
// ones before it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace vnsba::fuzz {

// splitmix64's finaliser: a good 64-bit mix, so neighbouring iterations get unrelated streams.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The generator seed of one input: independent of the other loaders and iterations.
inline uint64_t input_seed(uint64_t base_seed, std::string_view loader, uint64_t iteration) {
  uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a of the loader's name
  for (const char c : loader) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ull;
  return mix64(mix64(base_seed ^ h) + iteration);
}

// Which structural mutations make sense for a format.
enum class Syntax {
  kPlain,  // line-oriented text or binary: no nesting mutations
  kYaml,   // deep flow/block nesting inserted as a line or a value
  kJson,   // deep array/object nesting inserted as a value
};

class Mutator {
 public:
  Mutator(uint64_t seed, Syntax syntax, std::vector<std::string> dictionary = {})
      : rng_(seed), syntax_(syntax), dictionary_(std::move(dictionary)) {}

  // Numbers that sit on a boundary of some check: zero and negative zero, the edges of 8-, 16-,
  // 32- and 64-bit integers (signed and unsigned) and one past them, overflowing and subnormal
  // doubles, the spellings of NaN and infinity that strtod, from_chars, yaml-cpp and JSON see,
  // exponent forms, hexadecimal and the project's own limits (100000 cells per side, 2^28 cells).
  static const std::vector<std::string>& interesting_numbers() {
    // clang-format off
    static const std::vector<std::string> numbers = {
        // zero, signs, short forms
        "0", "-0", "0.0", "-0.0", "1", "-1", "2", "7", "+1", "+-1", "00", "0.5", ".5", "5.",
        // huge, overflowing, subnormal and underflowing doubles; exponent forms
        "1e308", "-1e308", "1e309", "-1e309", "1.7976931348623157e308", "1e-320", "4.9e-324",
        "2.2250738585072014e-308", "1e-400", "1.5e+3", "1e5", "1E3",
        // NaN and infinity as strtod, from_chars, yaml-cpp and JSON spell them
        "nan", "NaN", "-nan", ".nan", ".NaN", "inf", "-inf", "Infinity", ".inf", "-.inf",
        // integer edges and one past them
        "127", "128", "-128", "-129", "255", "256", "65535", "65536", "32767", "32768", "-32769",
        "2147483647", "2147483648", "-2147483648", "-2147483649", "4294967295", "4294967296",
        "0xffffffff", "0x7fffffff", "0x10", "9223372036854775807", "9223372036854775808",
        "-9223372036854775808", "-9223372036854775809", "18446744073709551615",
        "18446744073709551616", "99999999999999999999999999",
        // the project's limits: cells per side, max_cells, domain ids, seconds, weights
        "99999", "100000", "100001", "268435456", "268435457", "16777216", "232", "233", "3600",
        "3600.0000001", "1000000", "1e6", "1000001",
        // near misses
        "1_000", "1,5", "0.1.2", "--1", "1e", "e1", "1e+"};
    // clang-format on
    return numbers;
  }

  // Bytes that matter to these parsers: NUL, the line and token separators, comment and quote
  // characters, YAML/JSON structure, the sign and decimal point, the high bit and 0xff.
  static const std::string& interesting_bytes() {
    static constexpr char kBytes[] = "\0\n\r \t\v\f#:[]{},\"'-+.09@Ge\x7f\x80\xff";
    static const std::string bytes(kBytes, sizeof(kBytes) - 1);  // with the NUL
    return bytes;
  }

  // One input: `base` changed by 1 to 4 mutations, drawn from `seeds` for splicing. `log`
  // receives one line per mutation applied (for the failure report).
  std::string mutate(const std::string& base, const std::vector<std::string>& seeds,
                     std::vector<std::string>* log) {
    std::string s = base;
    const int count = 1 + static_cast<int>(below(4)) * static_cast<int>(below(2));  // 1 most often
    for (int i = 0; i < count; ++i) apply_one(s, seeds, log);
    return s;
  }

  uint64_t below(uint64_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<uint64_t>(0, n - 1)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }
  std::mt19937_64& rng() { return rng_; }

  // Inputs stay small enough for a few thousand a second under the sanitizers.
  static constexpr size_t kMaxSize = size_t{1} << 20;

 private:
  // Positions in `s` where a token or line starts or ends: where truncations and insertions
  // hurt most.
  std::vector<size_t> boundaries(const std::string& s) const {
    std::vector<size_t> out{0, s.size()};
    for (size_t i = 0; i < s.size(); ++i) {
      const char c = s[i];
      if (c == '\n' || c == '\r' || c == ' ' || c == '\t' || c == ':' || c == ',' || c == '[' ||
          c == ']' || c == '{' || c == '}' || c == '"') {
        out.push_back(i);
        out.push_back(i + 1);
      }
    }
    return out;
  }

  // [begin, end) of every maximal run of number characters holding a digit.
  static std::vector<std::pair<size_t, size_t>> number_tokens(const std::string& s) {
    auto number_char = [](char c) {
      return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E';
    };
    std::vector<std::pair<size_t, size_t>> out;
    for (size_t i = 0; i < s.size();) {
      if (!number_char(s[i])) {
        ++i;
        continue;
      }
      size_t j = i;
      bool digit = false;
      while (j < s.size() && number_char(s[j])) digit |= s[j] >= '0' && s[j] <= '9', ++j;
      if (digit) out.emplace_back(i, j);
      i = j;
    }
    return out;
  }

  // [begin, end) of every line, without its '\n'.
  static std::vector<std::pair<size_t, size_t>> lines(const std::string& s) {
    std::vector<std::pair<size_t, size_t>> out;
    for (size_t begin = 0; begin < s.size();) {
      size_t end = s.find('\n', begin);
      if (end == std::string::npos) end = s.size();
      out.emplace_back(begin, end);
      begin = end + 1;
    }
    return out;
  }

  std::string nesting(size_t depth) {
    std::string open, close;
    const uint64_t style = below(3);
    for (size_t i = 0; i < depth; ++i) {
      if (syntax_ == Syntax::kJson) {
        open += style == 0 ? "[" : "{\"a\":";
        close += style == 0 ? "]" : "}";
      } else {
        open += style == 0 ? "[" : style == 1 ? "{a: " : "- ";
        close += style == 0 ? "]" : style == 1 ? "}" : "";
      }
    }
    return open + (syntax_ == Syntax::kJson ? "1" : "x") + close;
  }

  void apply_one(std::string& s, const std::vector<std::string>& seeds,
                 std::vector<std::string>* log) {
    auto note = [&](const std::string& what) {
      if (log) log->push_back(what);
    };
    auto pos = [&](bool inclusive_end) { return below(s.size() + (inclusive_end ? 1 : 0)); };
    const uint64_t kinds = syntax_ == Syntax::kPlain ? 13 : 14;
    switch (below(kinds)) {
      case 0: {  // flip one bit
        if (s.empty()) break;
        const size_t p = pos(false);
        const unsigned bit = static_cast<unsigned>(below(8));
        s[p] = static_cast<char>(s[p] ^ (1u << bit));
        note("flip bit " + std::to_string(bit) + " of byte " + std::to_string(p));
        break;
      }
      case 1: {  // set a byte to an interesting value
        if (s.empty()) break;
        const size_t p = pos(false);
        const char c = interesting_bytes()[below(interesting_bytes().size())];
        s[p] = c;
        note("byte " + std::to_string(p) + " := " + std::to_string(static_cast<unsigned char>(c)));
        break;
      }
      case 2: {  // insert 1..8 interesting or random bytes, often at a boundary
        const std::vector<size_t> b = boundaries(s);
        const size_t p = chance(0.5) ? b[below(b.size())] : pos(true);
        std::string bytes;
        for (uint64_t n = 1 + below(8); n > 0; --n) {
          bytes.push_back(chance(0.5) ? interesting_bytes()[below(interesting_bytes().size())]
                                      : static_cast<char>(below(256)));
        }
        s.insert(p, bytes);
        note("insert " + std::to_string(bytes.size()) + " bytes at " + std::to_string(p));
        break;
      }
      case 3: {  // delete a range (short mostly, sometimes long)
        if (s.empty()) break;
        const size_t p = pos(false);
        const size_t n = 1 + below(chance(0.8) ? 8 : s.size() - p);
        s.erase(p, n);
        note("delete " + std::to_string(n) + " bytes at " + std::to_string(p));
        break;
      }
      case 4: {  // duplicate a range somewhere else (repeated keys, rows, nodes)
        if (s.empty()) break;
        const size_t p = pos(false);
        const size_t n = std::min<size_t>(1 + below(chance(0.8) ? 64 : s.size()), s.size() - p);
        const size_t at = pos(true);
        if (s.size() + n > kMaxSize) break;
        const std::string range = s.substr(p, n);
        s.insert(at, range);
        note("copy " + std::to_string(n) + " bytes from " + std::to_string(p) + " to " +
             std::to_string(at));
        break;
      }
      case 5: {  // truncate: at a token/line boundary, around it, at 0, 1 or the last byte
        const std::vector<size_t> b = boundaries(s);
        size_t p = 0;
        switch (below(4)) {
          case 0:
            p = b[below(b.size())];
            break;
          case 1:
            p = std::min(s.size(), b[below(b.size())] + below(3));
            break;
          case 2:
            p = std::vector<size_t>{0, 1, s.empty() ? 0 : s.size() - 1}[below(3)];
            break;
          default:
            p = pos(true);
            break;
        }
        s.resize(std::min(p, s.size()));
        note("truncate to " + std::to_string(s.size()) + " bytes");
        break;
      }
      case 6: {  // splice: a prefix of this input and a suffix of another seed
        if (seeds.empty()) break;
        const std::string& other = seeds[below(seeds.size())];
        const size_t cut = pos(true);
        const size_t from = below(other.size() + 1);
        s = s.substr(0, cut) + other.substr(from);
        if (s.size() > kMaxSize) s.resize(kMaxSize);
        note("splice: first " + std::to_string(cut) + " bytes, then another seed from " +
             std::to_string(from));
        break;
      }
      case 7:
      case 8: {  // replace a number with a boundary value (twice as likely: most checks are here)
        const auto tokens = number_tokens(s);
        if (tokens.empty()) break;
        const auto [begin, end] = tokens[below(tokens.size())];
        const std::string& value = interesting_numbers()[below(interesting_numbers().size())];
        note("number '" + s.substr(begin, end - begin) + "' at " + std::to_string(begin) + " := '" +
             value + "'");
        s.replace(begin, end - begin, value);
        break;
      }
      case 9: {  // replace a word with a dictionary word or a word from another seed
        const auto b = boundaries(s);
        if (b.size() < 2) break;
        const size_t begin = b[below(b.size())];
        size_t end = begin;
        while (end < s.size() &&
               std::string_view(" \t\r\n:,[]{}\"").find(s[end]) == std::string_view::npos) {
          ++end;
        }
        std::string word;
        if (!dictionary_.empty() && chance(0.7)) {
          word = dictionary_[below(dictionary_.size())];
        } else if (!seeds.empty()) {
          const std::string& other = seeds[below(seeds.size())];
          const size_t from = below(other.size() + 1);
          word = other.substr(from, below(12));
        }
        note("word at " + std::to_string(begin) + " := '" + word + "'");
        s.replace(begin, end - begin, word);
        break;
      }
      case 10: {  // repeat, delete or swap whole lines
        const auto ls = lines(s);
        if (ls.empty()) break;
        const auto [b1, e1] = ls[below(ls.size())];
        const std::string line = s.substr(b1, e1 - b1);
        const uint64_t what = below(3);
        if (what == 0) {
          const size_t times = chance(0.9) ? 1 : 1 + below(200);
          std::string copies;
          for (size_t i = 0; i < times; ++i) copies += line + "\n";
          if (s.size() + copies.size() > kMaxSize) break;
          s.insert(b1, copies);
          note("repeat line at " + std::to_string(b1) + " x" + std::to_string(times));
        } else if (what == 1) {
          s.erase(b1, std::min(s.size(), e1 + 1) - b1);
          note("delete line at " + std::to_string(b1));
        } else {
          const auto [b2, e2] = ls[below(ls.size())];
          if (b2 == b1) break;
          const std::string other = s.substr(b2, e2 - b2);
          // Replace the later one first so the earlier offsets stay valid.
          if (b2 > b1) {
            s.replace(b2, e2 - b2, line);
            s.replace(b1, e1 - b1, other);
          } else {
            s.replace(b1, e1 - b1, other);
            s.replace(b2, e2 - b2, line);
          }
          note("swap lines at " + std::to_string(b1) + " and " + std::to_string(b2));
        }
        break;
      }
      case 11: {  // line endings: LF <-> CRLF on one line or everywhere, or a lone CR
        const uint64_t what = below(3);
        if (what == 0) {
          std::string out;
          for (const char c : s) {
            if (c == '\n') out += '\r';
            out += c;
          }
          if (out.size() <= kMaxSize) s = out;
          note("all line ends CRLF");
        } else if (what == 1) {
          s.erase(std::remove(s.begin(), s.end(), '\r'), s.end());
          note("all CR removed");
        } else {
          const size_t p = s.find('\n', pos(true));
          if (p != std::string::npos) s[p] = '\r';
          note("one LF := CR");
        }
        break;
      }
      case 12: {  // a long run of one byte (long tokens, long lines, huge numbers)
        const size_t p = pos(true);
        const size_t n = std::vector<size_t>{64, 1000, 70000}[below(3)];
        if (s.size() + n > kMaxSize) break;
        const char c = chance(0.5) ? '9' : interesting_bytes()[below(interesting_bytes().size())];
        s.insert(p, std::string(n, c));
        note("insert " + std::to_string(n) + " x byte " +
             std::to_string(static_cast<unsigned char>(c)) + " at " + std::to_string(p));
        break;
      }
      default: {  // deep nesting (YAML, JSON): as a value replacing a number, or a new line
        const size_t depth = std::vector<size_t>{16, 300, 1999, 2001, 5000, 100000}[below(6)];
        const std::string nested = nesting(depth);
        if (s.size() + nested.size() + 8 > kMaxSize) break;
        const auto tokens = number_tokens(s);
        if (!tokens.empty() && chance(0.6)) {
          const auto [begin, end] = tokens[below(tokens.size())];
          s.replace(begin, end - begin, nested);
          note("number at " + std::to_string(begin) + " := nesting of depth " +
               std::to_string(depth));
        } else {
          const auto ls = lines(s);
          const size_t at = ls.empty() ? 0 : ls[below(ls.size())].first;
          const std::string line = syntax_ == Syntax::kJson ? nested : "k: " + nested + "\n";
          s.insert(at, line);
          note("nesting of depth " + std::to_string(depth) + " inserted at " + std::to_string(at));
        }
        break;
      }
    }
  }

  std::mt19937_64 rng_;
  Syntax syntax_;
  std::vector<std::string> dictionary_;
};

}  // namespace vnsba::fuzz
