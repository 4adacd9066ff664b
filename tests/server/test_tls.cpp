// TLS on the HTTP listener (--tls-cert/--tls-key): HTTPS for the preview page,
// WSS for /ws, plain HTTP refused on the TLS port, and clear errors for files
// that cannot be loaded. The certificate is made here, in code, per test run.
#include <gtest/gtest.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>

#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using TlsStream = beast::ssl_stream<beast::tcp_stream>;

// Client-side deadline: a broken server fails the test instead of hanging it.
constexpr auto kClientDeadline = std::chrono::seconds(20);

// A fresh temporary directory, removed with the object.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("beamcast-tls-" + std::to_string(::getpid()) + "-" +
            std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

void write_pem(const fs::path& file, const std::function<int(FILE*)>& write) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(file.c_str(), "w"), &std::fclose);
  if (!f || write(f.get()) != 1) throw std::runtime_error("cannot write " + file.string());
}

// A self-signed P-256 certificate for CN=127.0.0.1, valid for a day, and its
// private key, as PEM files.
void make_self_signed(const fs::path& cert_file, const fs::path& key_file) {
  std::unique_ptr<EVP_PKEY, void (*)(EVP_PKEY*)> key(EVP_EC_gen("P-256"), &EVP_PKEY_free);
  ASSERT_TRUE(key);
  std::unique_ptr<X509, void (*)(X509*)> cert(X509_new(), &X509_free);
  ASSERT_TRUE(cert);
  X509_set_version(cert.get(), 2);  // v3
  ASN1_INTEGER_set(X509_get_serialNumber(cert.get()), 1);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -60);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), 24 * 3600);
  X509_set_pubkey(cert.get(), key.get());
  X509_NAME* name = X509_get_subject_name(cert.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC,
                             reinterpret_cast<const unsigned char*>("127.0.0.1"), -1, -1, 0);
  X509_set_issuer_name(cert.get(), name);
  ASSERT_GT(X509_sign(cert.get(), key.get(), EVP_sha256()), 0);
  write_pem(cert_file, [&](FILE* f) { return PEM_write_X509(f, cert.get()); });
  write_pem(key_file, [&](FILE* f) {
    return PEM_write_PrivateKey(f, key.get(), nullptr, nullptr, 0, nullptr, nullptr);
  });
}

// A client TLS context that trusts exactly the test's certificate.
asio::ssl::context trusting(const fs::path& cert_file) {
  asio::ssl::context ctx(asio::ssl::context::tls_client);
  ctx.load_verify_file(cert_file.string());
  ctx.set_verify_mode(asio::ssl::verify_peer);
  return ctx;
}

struct TlsServerTest : ::testing::Test {
  TempDir dir;
  fs::path cert = dir.path / "cert.pem";
  fs::path key = dir.path / "key.pem";
  void SetUp() override { make_self_signed(cert, key); }
  ServerConfig config() const {
    ServerConfig c;
    c.http_port = 0;
    c.tls_cert_file = cert.string();
    c.tls_key_file = key.string();
    return c;
  }
};

TEST_F(TlsServerTest, ServesThePageOverHttpsAndTheProtocolOverWss) {
  test::LocalServer s(config());
  asio::io_context io;
  asio::ssl::context ctx = trusting(cert);
  const tcp::endpoint ep(asio::ip::make_address("127.0.0.1"), s.http_port());
  {
    TlsStream stream(io, ctx);
    beast::get_lowest_layer(stream).expires_after(kClientDeadline);
    beast::get_lowest_layer(stream).connect(ep);
    stream.handshake(asio::ssl::stream_base::client);  // throws if the certificate is not ours
    http::request<http::string_body> req{http::verb::get, "/", 11};
    req.set(http::field::host, "127.0.0.1");
    http::write(stream, req);
    beast::flat_buffer buf;
    http::response<http::string_body> res;
    http::read(stream, buf, res);
    EXPECT_EQ(res.result_int(), 200);
    EXPECT_NE(res[http::field::content_type].find("text/html"), std::string::npos);
    EXPECT_NE(res.body().find("<title>Beamcast preview</title>"), std::string::npos);
    // A second request on the same TLS connection (keep-alive works over TLS).
    req.target("/api/scenes");
    http::write(stream, req);
    http::response<http::string_body> scenes;
    http::read(stream, buf, scenes);
    EXPECT_EQ(scenes.result_int(), 200);
  }
  {
    websocket::stream<TlsStream> ws(io, ctx);
    beast::get_lowest_layer(ws).expires_after(kClientDeadline);
    beast::get_lowest_layer(ws).connect(ep);
    ws.next_layer().handshake(asio::ssl::stream_base::client);
    beast::get_lowest_layer(ws).expires_never();  // the WebSocket's own timeouts from here
    ws.handshake("127.0.0.1", "/ws");
    ws.text(true);
    ws.write(asio::buffer(std::string(R"({"id":7,"method":"ping"})")));
    beast::flat_buffer buf;
    ws.read(buf);
    const auto j = nlohmann::json::parse(beast::buffers_to_string(buf.data()));
    EXPECT_EQ(j.value("id", 0), 7);
    EXPECT_TRUE(j.value("ok", false)) << j.dump();
    ws.close(websocket::close_code::normal);
  }
}

TEST_F(TlsServerTest, PlainHttpOnTheTlsPortGetsNoPage) {
  test::LocalServer s(config());
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.expires_after(kClientDeadline);
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), s.http_port()));
  const std::string req = "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  asio::write(stream, asio::buffer(req));
  // Read whatever comes back until the server closes the connection (at most
  // a TLS alert record); a deadline error would also end the loop.
  std::string got;
  beast::error_code ec;
  char chunk[4096];
  for (;;) {
    const std::size_t n = stream.read_some(asio::buffer(chunk), ec);
    got.append(chunk, n);
    if (ec) break;
  }
  EXPECT_NE(ec, beast::error::timeout) << "the server should close the connection, not idle";
  EXPECT_FALSE(got.starts_with("HTTP/")) << got.substr(0, 64);
  EXPECT_EQ(got.find("Beamcast preview"), std::string::npos);
}

TEST_F(TlsServerTest, PlainListenerStaysPlainWithoutTls) {
  ServerConfig c;
  c.http_port = 0;
  test::LocalServer s(c);
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.expires_after(kClientDeadline);
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), s.http_port()));
  http::request<http::string_body> req{http::verb::get, "/", 11};
  req.set(http::field::host, "127.0.0.1");
  http::write(stream, req);
  beast::flat_buffer buf;
  http::response<http::string_body> res;
  http::read(stream, buf, res);
  EXPECT_EQ(res.result_int(), 200);
  EXPECT_NE(res.body().find("<title>Beamcast preview</title>"), std::string::npos);
}

// Server::start must throw `what` (a substring) for config `c`.
void expect_start_error(ServerConfig c, const std::string& what) {
  c.port = 0;
  Server server(c, gl_renderer_factory({}));
  try {
    server.start();
    ADD_FAILURE() << "start() accepted a bad TLS configuration; expected: " << what;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST_F(TlsServerTest, FilesThatCannotBeLoadedAreClearErrors) {
  ServerConfig c = config();
  c.tls_cert_file = (dir.path / "missing.pem").string();
  expect_start_error(c, "cannot load TLS certificate (PEM) from '" + c.tls_cert_file + "'");

  c = config();
  c.tls_key_file = cert.string();  // a certificate is not a key
  expect_start_error(c, "cannot load TLS private key (PEM) from '" + cert.string() + "'");

  // A valid key that belongs to another certificate.
  const fs::path other_cert = dir.path / "other-cert.pem", other_key = dir.path / "other-key.pem";
  make_self_signed(other_cert, other_key);
  c = config();
  c.tls_key_file = other_key.string();
  expect_start_error(c, "does not match certificate");

  c = config();
  c.tls_key_file.clear();
  expect_start_error(c, "both a certificate and a private key");

  c = config();
  c.http_port = -1;
  expect_start_error(c, "HTTP listener, which is off");
}

}  // namespace
}  // namespace beamcast
