// SHA-256 over OpenSSL's EVP interface (libcrypto from libssl-dev).
#include "common/sha256.hpp"

#include <openssl/evp.h>

#include <stdexcept>

namespace dermis {

Sha256Digest sha256(const void* data, std::size_t size) {
    Sha256Digest out{};
    unsigned int length = 0;
    static const unsigned char empty = 0;
    if (EVP_Digest(data ? data : &empty, size, out.data(), &length, EVP_sha256(), nullptr) != 1 ||
        length != out.size())
        throw std::runtime_error("dermis::sha256: EVP_Digest failed");
    return out;
}

std::string toHex(const Sha256Digest& digest) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    s.reserve(digest.size() * 2);
    for (std::uint8_t b : digest) {
        s.push_back(digits[b >> 4]);
        s.push_back(digits[b & 15]);
    }
    return s;
}

Sha256::Sha256() : ctx_(EVP_MD_CTX_new()) {
    if (!ctx_ || EVP_DigestInit_ex(static_cast<EVP_MD_CTX*>(ctx_), EVP_sha256(), nullptr) != 1)
        throw std::runtime_error("dermis::Sha256: EVP_DigestInit_ex failed");
}

Sha256::~Sha256() { EVP_MD_CTX_free(static_cast<EVP_MD_CTX*>(ctx_)); }

void Sha256::update(const void* data, std::size_t size) {
    if (size == 0) return;
    if (EVP_DigestUpdate(static_cast<EVP_MD_CTX*>(ctx_), data, size) != 1)
        throw std::runtime_error("dermis::Sha256::update: EVP_DigestUpdate failed");
}

Sha256Digest Sha256::finish() {
    Sha256Digest out{};
    unsigned int length = 0;
    if (EVP_DigestFinal_ex(static_cast<EVP_MD_CTX*>(ctx_), out.data(), &length) != 1 || length != out.size())
        throw std::runtime_error("dermis::Sha256::finish: EVP_DigestFinal_ex failed");
    return out;
}

} // namespace dermis
