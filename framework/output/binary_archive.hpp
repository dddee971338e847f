// The bytes of a checkpoint (framework/output/checkpoint.hpp): values appended to a string as they
// are in memory, and read back in the same order. A checkpoint is resumed by the build and machine
// kind that wrote it (its header says which), so no byte order or width is translated; what this
// guards against is a file cut short or damaged, which must be refused, never read past its end.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "framework/api/errors.hpp"

namespace gem {

class BinaryWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "BinaryWriter::put: a value copied as bytes");
    m_bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  template <class A, class B>
  void put(const std::pair<A, B>& pair) {
    put(pair.first), put(pair.second);
  }
  void put(const std::string& text) {
    put(static_cast<std::uint64_t>(text.size()));
    m_bytes.append(text);
  }
  template <class T>
  void put(const std::vector<T>& values) {
    put(static_cast<std::uint64_t>(values.size()));
    if constexpr (std::is_trivially_copyable_v<T>) {
      m_bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    } else {
      for (const T& v : values) put(v);
    }
  }
  const std::string& bytes() const { return m_bytes; }

 private:
  std::string m_bytes;
};

class BinaryReader {
 public:
  // what: the file, for the message when the bytes run out or a count is impossible.
  BinaryReader(const std::string& bytes, std::string what) : m_bytes(bytes), m_what(std::move(what)) {}

  template <class T>
  void get(T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "BinaryReader::get: a value copied as bytes");
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
  }
  template <class A, class B>
  void get(std::pair<A, B>& pair) {
    get(pair.first), get(pair.second);
  }
  void get(std::string& text) {
    const std::uint64_t n = count(1);
    text.assign(take(n), n);
  }
  template <class T>
  void get(std::vector<T>& values) {
    if constexpr (std::is_trivially_copyable_v<T>) {
      const std::uint64_t n = count(sizeof(T));
      values.resize(n);
      if (n) std::memcpy(values.data(), take(n * sizeof(T)), n * sizeof(T));
    } else {
      const std::uint64_t n = count(1);
      values.resize(n);
      for (T& v : values) get(v);
    }
  }
  template <class T>
  T get() {
    T value{};
    get(value);
    return value;
  }
  bool atEnd() const { return m_at == m_bytes.size(); }

 private:
  // A count read from the file, checked against the bytes left (each element at least `least`
  // bytes): a damaged count must not allocate gigabytes before the read runs out.
  std::uint64_t count(std::uint64_t least) {
    const auto n = get<std::uint64_t>();
    if (n > (m_bytes.size() - m_at) / least)
      throw InputError(m_what + ": damaged (a count of " + std::to_string(n) + " runs past its end)");
    return n;
  }
  const char* take(std::uint64_t n) {
    if (n > m_bytes.size() - m_at) throw InputError(m_what + ": cut short (it ends inside a value)");
    const char* at = m_bytes.data() + m_at;
    m_at += n;
    return at;
  }
  const std::string& m_bytes;
  std::string m_what;
  size_t m_at = 0;
};

}  // namespace gem
