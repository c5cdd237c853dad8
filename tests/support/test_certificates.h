// Throw-away PKI for the TLS tests, made with the `openssl` command line as an operator would:
// a CA, a server certificate for 127.0.0.1 and localhost, a client certificate from the CA, and
// a second, "rogue" CA with a client certificate of its own. EC P-256 keys: the whole set takes
// ~0.1 s to make. Header-only so that any test binary can use it.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace inscribe::testing {

struct TestCertificates {
  std::filesystem::path dir;  // holds everything below; removed by Remove()
  std::string ca;             // PEM certificate of the CA
  std::string server_cert;    // signed by `ca`; subjectAltName IP:127.0.0.1, DNS:localhost
  std::string server_key;
  std::string client_cert;  // signed by `ca`, for client authentication
  std::string client_key;
  std::string rogue_ca;    // a CA nobody trusts
  std::string rogue_cert;  // a client certificate signed by `rogue_ca`
  std::string rogue_key;
  std::string error;  // empty when every file was made; else what failed (openssl's log)

  // Writes `text` to dir/name (a token file, a broken PEM file, ...); its path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = dir / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }

  void Remove() const {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
};

namespace certificates_internal {

// Runs `command` with stdout and stderr appended to `log`; whether it exited 0.
inline bool Run(const std::string& command, const std::filesystem::path& log) {
  const std::string line = command + " >>'" + log.string() + "' 2>&1";
  return std::system(line.c_str()) == 0;
}

inline std::string Quote(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

// A key and a self-signed CA certificate (the default config's v3_ca: CA:TRUE).
inline bool MakeCa(const std::filesystem::path& dir, const std::string& name,
                   const std::filesystem::path& log) {
  return Run(
      "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 "
      "-subj /CN=" +
          name + " -keyout " + Quote(dir / (name + ".key")) + " -out " +
          Quote(dir / (name + ".pem")),
      log);
}

// A key and a certificate for `name` signed by CA `ca`, with the extensions in `extensions`.
inline bool MakeLeaf(const std::filesystem::path& dir, const std::string& name,
                     const std::string& ca, const std::string& extensions, int serial,
                     const std::filesystem::path& log) {
  const std::filesystem::path ext = dir / (name + ".ext");
  std::ofstream(ext) << extensions;
  return Run("openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -subj /CN=" +
                 name + " -keyout " + Quote(dir / (name + ".key")) + " -out " +
                 Quote(dir / (name + ".csr")),
             log) &&
         Run("openssl x509 -req -days 2 -set_serial " + std::to_string(serial) + " -in " +
                 Quote(dir / (name + ".csr")) + " -CA " + Quote(dir / (ca + ".pem")) + " -CAkey " +
                 Quote(dir / (ca + ".key")) + " -extfile " + Quote(ext) + " -out " +
                 Quote(dir / (name + ".pem")),
             log);
}

}  // namespace certificates_internal

inline TestCertificates MakeTestCertificates() {
  namespace ci = certificates_internal;
  TestCertificates out;
  out.dir = std::filesystem::temp_directory_path() /
            ("inscribe-certs-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(out.dir);
  const std::filesystem::path log = out.dir / "openssl.log";
  const std::filesystem::path& d = out.dir;
  const bool made =
      ci::MakeCa(d, "ca", log) && ci::MakeCa(d, "rogue-ca", log) &&
      ci::MakeLeaf(d, "server", "ca",
                   "subjectAltName=IP:127.0.0.1,DNS:localhost\nbasicConstraints=CA:FALSE\n"
                   "extendedKeyUsage=serverAuth\n",
                   2, log) &&
      ci::MakeLeaf(d, "client", "ca", "basicConstraints=CA:FALSE\nextendedKeyUsage=clientAuth\n", 3,
                   log) &&
      ci::MakeLeaf(d, "rogue", "rogue-ca",
                   "basicConstraints=CA:FALSE\nextendedKeyUsage=clientAuth\n", 4, log);
  if (!made) {
    std::ifstream in(log);
    out.error = "openssl failed: " + std::string(std::istreambuf_iterator<char>(in), {});
  }
  out.ca = (d / "ca.pem").string();
  out.server_cert = (d / "server.pem").string();
  out.server_key = (d / "server.key").string();
  out.client_cert = (d / "client.pem").string();
  out.client_key = (d / "client.key").string();
  out.rogue_ca = (d / "rogue-ca.pem").string();
  out.rogue_cert = (d / "rogue.pem").string();
  out.rogue_key = (d / "rogue.key").string();
  return out;
}

}  // namespace inscribe::testing
