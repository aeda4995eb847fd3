// The "C" locale on the calling thread for a scope, whatever the host program set from its
// user's language (Maya follows its UI language): text read there reads as it was written.
#pragma once

#include <locale.h>

namespace footfall {

// Sets the calling thread's locale to "C" (uselocale) and puts back the thread's previous one
// when it goes out of scope; the rest of the process keeps the host's. The JSON reader takes
// LC_NUMERIC's decimal point, one byte of it: in a Pashto locale, whose decimal point is two
// bytes, [10.75, 0, 10.75] read as [10, 0, 10].
class CLocaleScope {
 public:
  CLocaleScope() : previous_(CLocale() ? uselocale(CLocale()) : nullptr) {}
  ~CLocaleScope() {
    if (CLocale()) uselocale(previous_);
  }
  CLocaleScope(const CLocaleScope&) = delete;
  CLocaleScope& operator=(const CLocaleScope&) = delete;

 private:
  static locale_t CLocale() {
    static const locale_t c = newlocale(LC_ALL_MASK, "C", nullptr);
    return c;
  }
  const locale_t previous_;
};

}  // namespace footfall
