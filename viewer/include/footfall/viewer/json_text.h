// JsonText: JSON written value by value, laid out as nlohmann's dump(2) lays a document out,
// with no document held. A document of nlohmann's objects and arrays allocates as it is
// destroyed, and an exception there ends the process: memory running out while one was built
// for --dump-state ended the viewer.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace footfall::viewer {

class JsonText {
 public:
  // Opens an object or array: the document itself, a member after Key, or an array's element.
  void BeginObject() { Open('{'); }
  void BeginArray() { Open('['); }
  // Closes the innermost open object or array ("{}" or "[]" when nothing was written in it).
  void End() {
    const bool empty = open_.back() == 'e';
    open_.pop_back();
    if (!empty) {
      text_ += '\n';
      text_.append(2 * open_.size(), ' ');
    }
    text_ += closing_.back();
    closing_.pop_back();
  }
  // Names the next member of the innermost object.
  JsonText& Key(const std::string& key) {
    Element();
    Scalar(nlohmann::json(key));
    text_ += ": ";
    after_key_ = true;
    return *this;
  }
  // Values, each an array element or the member Key named. Strings that are not valid UTF-8
  // have their bad bytes replaced (U+FFFD), as the viewer's other outputs do.
  void Value(const std::string& v) { Put(nlohmann::json(v)); }
  void Value(const char* v) { Put(nlohmann::json(v)); }
  void Value(double v) { Put(nlohmann::json(v)); }
  void Value(int64_t v) { Put(nlohmann::json(v)); }
  void Value(uint64_t v) { Put(nlohmann::json(v)); }
  void Value(int v) { Put(nlohmann::json(v)); }
  void Value(bool v) { Put(nlohmann::json(v)); }
  void Null() { Put(nlohmann::json(nullptr)); }
  // The text so far (the whole document once every Begin has its End).
  const std::string& text() const { return text_; }

 private:
  // Before an element: the comma after the one before it, a new line and the indentation.
  void Element() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (open_.empty()) return;
    if (open_.back() == 'n') text_ += ',';
    open_.back() = 'n';
    text_ += '\n';
    text_.append(2 * open_.size(), ' ');
  }
  void Open(char bracket) {
    Element();
    text_ += bracket;
    open_ += 'e';
    closing_ += bracket == '{' ? '}' : ']';
  }
  // A scalar json value (it holds no children: destroying it allocates nothing).
  void Scalar(const nlohmann::json& v) {
    text_ += v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  void Put(const nlohmann::json& v) {
    Element();
    Scalar(v);
  }

  std::string text_;
  std::string open_;     // per open container: 'e' while empty, 'n' once not
  std::string closing_;  // their closing brackets
  bool after_key_ = false;
};

}  // namespace footfall::viewer
