// UTF-8 repair of client-quoted text in error responses. Regression for the
// first fuzz_request finding: a request with an invalid UTF-8 byte made the
// JSON parser's error message (which quotes the bytes read) unserializable,
// and the server's send threw out of the io_context (docs/fuzzing.md).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "protocol/request.hpp"
#include "protocol/utf8.hpp"

namespace beamcast {
namespace {

TEST(Utf8, ValidInputIsUnchanged) {
  for (const std::string& s : std::initializer_list<std::string>{"", "abc", "\xC3\xA9t\xC3\xA9", "\xE2\x82\xAC", "\xF0\x9F\x98\x80",
                              "\xF4\x8F\xBF\xBF", std::string("nul\0byte", 8)}) {
    EXPECT_TRUE(is_valid_utf8(s)) << s;
    EXPECT_EQ(to_valid_utf8(s), s);
  }
}

TEST(Utf8, EachInvalidByteBecomesOneReplacementCharacter) {
  const std::string fffd = "\xEF\xBF\xBD";
  struct Case {
    std::string in, out;
  };
  const Case cases[] = {
      {"a\x80z", "a" + fffd + "z"},                 // lone continuation byte
      {"\xC3", fffd},                               // truncated 2-byte sequence
      {"\xE2\x82", fffd + fffd},                    // truncated 3-byte sequence
      {"\xC0\xAF", fffd + fffd},                    // overlong '/'
      {"\xE0\x80\xAF", fffd + fffd + fffd},         // overlong 3-byte
      {"\xED\xA0\x80", fffd + fffd + fffd},         // UTF-16 surrogate
      {"\xF4\x90\x80\x80", fffd + fffd + fffd + fffd},  // above U+10FFFF
      {"\xFF", fffd},
  };
  for (const Case& c : cases) {
    EXPECT_FALSE(is_valid_utf8(c.in));
    EXPECT_EQ(to_valid_utf8(c.in), c.out);
    EXPECT_TRUE(is_valid_utf8(to_valid_utf8(c.in)));
  }
}

TEST(Utf8, ParseErrorOfInvalidBytesGivesASerializableErrorResponse) {
  // The fuzz input fuzz/corpus/fuzz_request/regress_invalid_utf8_in_parse_error.
  const std::string text = "{\"id\":4,\"method\":\"render\",\"params\":{\"scene\":{},\"scene_i\x9c\xdd\xc5\xd7x\"}}";
  nlohmann::json id;
  try {
    parse_request(text, &id);
    FAIL() << "invalid UTF-8 must not parse";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "bad_json");
    const nlohmann::json r = error_response(id, e.info());
    EXPECT_NO_THROW((void)r.dump());  // strict handler, as nlohmann's default
  }
}

}  // namespace
}  // namespace beamcast
