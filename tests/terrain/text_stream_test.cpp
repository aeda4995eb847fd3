// TextStream, the stream messages, stop reasons and overlays are written with: whole or an
// exception when memory runs out while it is written (counted by this executable's own operator
// new, which fails while asked to), and the "C" locale whatever the host set.
#include <atomic>
#include <cstdlib>
#include <locale>
#include <new>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/terrain/text_stream.h"

namespace {

std::atomic<bool> g_failing{false};  // every allocation fails while set

void* Allocated(size_t n) {
  if (g_failing.load()) throw std::bad_alloc();
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}

// Writes `text` after "stop: " into `stream` with every allocation failing during the write.
template <class Stream>
void WriteWhileMemoryFails(Stream& stream, const std::string& text) {
  stream << "stop: ";
  g_failing = true;
  stream << text;
  g_failing = false;
}

}  // namespace

void* operator new(size_t n) { return Allocated(n); }
void* operator new[](size_t n) { return Allocated(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }

using footfall::TextStream;

TEST_CASE("TextStream: a text written while memory ran out is an exception, never cut short",
          "[terrain][text]") {
  const std::string reason(300, 'x');  // beyond what the stream holds without allocating
  // What it guards against: a plain string stream swallows the failure and keeps what it had.
  std::ostringstream plain;
  WriteWhileMemoryFails(plain, reason);
  REQUIRE(plain.bad());
  const std::string cut = plain.str();  // what its buffer held room for
  REQUIRE(cut.size() < 6 + reason.size());
  REQUIRE(cut == ("stop: " + reason).substr(0, cut.size()));

  TextStream text;
  WriteWhileMemoryFails(text, reason);
  CHECK(text.bad());
  CHECK_THROWS_AS(text.str(), std::bad_alloc);

  // Written with memory to spare, it is the whole text; str("") empties it.
  TextStream whole;
  whole << "stop: " << reason;
  CHECK(whole.str() == "stop: " + reason);
  whole.str("");
  whole << 1;
  CHECK(whole.str() == "1");
}

TEST_CASE("TextStream: numbers in the C locale whatever the global C++ locale is",
          "[terrain][text]") {
  // A host (Maya follows its UI language) may set the global locale from its user's: German
  // groups thousands with '.' and writes ',' for the decimal point.
  std::locale german;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8"}) {
    try {
      german = std::locale(name);
      break;
    } catch (const std::runtime_error&) {
    }
  }
  if (german.name() == "C") FAIL("no German locale installed: run scripts/install-deps.sh test");
  const std::locale before = std::locale::global(german);
  std::ostringstream host;
  host << 1234567.5 << " " << 1234567;
  TextStream text(9);
  text << 1234567.5 << " " << 1234567;
  std::locale::global(before);
  CHECK(host.str() != "1234567.5 1234567");  // the host's locale reaches a plain stream
  CHECK(text.str() == "1234567.5 1234567");
  TextStream three(3);
  three << 2.0 / 3;
  CHECK(three.str() == "0.667");
}
