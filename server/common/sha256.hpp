// Dermis common (server and client) — SHA-256 digests through OpenSSL's libcrypto (EVP_Digest), for content-addressed
// uploads (the same model or pattern bytes get the same id) and manifests.
// Pure functions of their input; no state, thread-safe. What it does not do: keyed hashes (HMAC),
// streaming over files (hash what is in memory).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

using Sha256Digest = std::array<std::uint8_t, 32>;

/// The SHA-256 of `size` bytes at `data` (`data` may be null when `size` is 0). libcrypto's
/// SHA-256 cannot fail on valid memory; if EVP_Digest reports a failure anyway (a broken
/// OpenSSL installation), the function throws std::runtime_error naming itself.
Sha256Digest sha256(const void* data, std::size_t size);
inline Sha256Digest sha256(const std::vector<std::uint8_t>& bytes) { return sha256(bytes.data(), bytes.size()); }
inline Sha256Digest sha256(std::string_view text) { return sha256(text.data(), text.size()); }

/// Lower-case hexadecimal digits of a digest (64 characters).
std::string toHex(const Sha256Digest& digest);

/// An incremental SHA-256 over several pieces (the concatenation's digest). Not copyable.
class Sha256 {
public:
    Sha256();
    ~Sha256();
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;
    void update(const void* data, std::size_t size);
    void update(std::string_view text) { update(text.data(), text.size()); }
    /// The digest of everything given so far; the object may not be updated afterwards.
    Sha256Digest finish();

private:
    void* ctx_; ///< EVP_MD_CTX*
};

} // namespace dermis
