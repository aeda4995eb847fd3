#include "text_numbers.h"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace footfall::detail {

bool IsMicrosoftNonFinite(std::string_view token) {
  size_t i = 0;
  auto digits = [&] {
    const size_t from = i;
    while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i]))) ++i;
    return i > from;
  };
  if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
  if (!digits()) return false;
  if (i < token.size() && token[i] == '.') ++i, digits();
  if (i >= token.size() || token[i++] != '#') return false;
  size_t word = 0;
  for (const char* name : {"QNAN", "SNAN", "IND", "INF"}) {
    const size_t n = std::strlen(name);
    if (token.size() - i >= n && std::equal(name, name + n, token.begin() + i, [](char a, char b) {
          return a == std::toupper(static_cast<unsigned char>(b));
        })) {
      word = n;
      break;
    }
  }
  if (word == 0) return false;
  i += word;
  digits();
  if (i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
    ++i;
    if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
    if (!digits()) return false;
  }
  return i == token.size();
}

std::string NotFiniteNote(std::string_view token) {
  return IsMicrosoftNonFinite(token) ? " (Microsoft C's NaN or infinity)" : "";
}

size_t CommentStart(std::string_view line) {
  for (size_t at = line.find('#'); at != std::string_view::npos; at = line.find('#', at + 1)) {
    const size_t begin = line.find_last_of(" \t\r\n\f\v", at);
    const size_t start = begin == std::string_view::npos ? 0 : begin + 1;
    const size_t end = std::min(line.find_first_of(" \t\r\n\f\v", at), line.size());
    if (start == at || !IsMicrosoftNonFinite(line.substr(start, end - start))) return at;
    at = end == 0 ? at : end - 1;
  }
  return std::string_view::npos;
}

bool IsMicrosoftNaN(std::string_view token) {
  if (!IsMicrosoftNonFinite(token)) return false;
  const size_t hash = token.find('#');  // then QNAN, SNAN, IND or INF
  return std::toupper(static_cast<unsigned char>(token[hash + 1])) != 'I' ||
         std::toupper(static_cast<unsigned char>(token[hash + 3])) == 'D';
}

}  // namespace footfall::detail
