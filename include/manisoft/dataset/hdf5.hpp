// A thin RAII layer over the HDF5 C library (Debian's libhdf5-dev) for the expert dataset: owned
// handles, typed writes and reads of whole datasets and attributes, and errors that name the file
// and the object path ("episodes/demo_3.hdf5: /data/demo_3/actions: ..."). HDF5's own error
// printing is switched off only while one of these calls runs (ScopedSilence), then restored.
#pragma once

#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "manisoft/core/error.hpp"

namespace manisoft::dataset::h5 {

/// Switches HDF5's automatic error printing off for its lifetime and restores what was there.
class ScopedSilence {
 public:
  ScopedSilence() {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~ScopedSilence() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }
  ScopedSilence(const ScopedSilence&) = delete;
  ScopedSilence& operator=(const ScopedSilence&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

/// An owned HDF5 identifier, closed with the close function of its kind.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)), closer_(other.closer_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      closer_ = other.closer_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; returns false if HDF5 reported a failure (a write that did not reach the disk).
  bool reset() {
    bool ok = true;
    if (id_ >= 0 && closer_ != nullptr) ok = closer_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return ok;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

template <typename... Parts>
[[noreturn]] void fail_at(const std::string& file, const std::string& path, Parts&&... parts) {
  ::manisoft::detail::fail(file, ": ", path, ": ", std::forward<Parts>(parts)...);
}

/// The HDF5 memory type of a C++ element type.
template <typename T>
hid_t native_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, float>) return H5T_NATIVE_FLOAT;
  else if constexpr (std::is_same_v<T, std::uint8_t>) return H5T_NATIVE_UINT8;
  else if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
  else static_assert(sizeof(T) == 0, "unsupported element type");
}

/// An open HDF5 file that remembers its name for error messages.
class File {
 public:
  /// Creates (truncating) a file for writing.
  static File create(const std::string& name) {
    ScopedSilence silence;
    const hid_t id = H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (id < 0) ::manisoft::detail::fail(name, ": cannot create the HDF5 file (folder missing or not writable?)");
    return File(name, Handle(id, H5Fclose));
  }
  /// Opens an existing file read-only.
  static File open(const std::string& name) {
    ScopedSilence silence;
    if (H5Fis_hdf5(name.c_str()) <= 0) ::manisoft::detail::fail(name, ": not a readable HDF5 file (missing, truncated or corrupted)");
    const hid_t id = H5Fopen(name.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id < 0) ::manisoft::detail::fail(name, ": cannot open the HDF5 file (truncated or corrupted?)");
    return File(name, Handle(id, H5Fclose));
  }

  const std::string& name() const { return name_; }
  hid_t id() const { return handle_.get(); }

  /// Flushes and closes; throws if HDF5 could not write everything.
  void close() {
    ScopedSilence silence;
    if (handle_.valid() && H5Fflush(handle_.get(), H5F_SCOPE_GLOBAL) < 0) ::manisoft::detail::fail(name_, ": flushing the HDF5 file failed");
    if (!handle_.reset()) ::manisoft::detail::fail(name_, ": closing the HDF5 file failed");
  }

  /// Creates the groups of `path` ("/data/demo_3/obs") that do not exist yet.
  void create_groups(const std::string& path) {
    ScopedSilence silence;
    std::size_t at = 1;
    while (at <= path.size()) {
      const std::size_t end = path.find('/', at);
      const std::string prefix = path.substr(0, end);
      if (H5Lexists(id(), prefix.c_str(), H5P_DEFAULT) <= 0) {
        Handle untimed(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);  // no modification times: same content, same bytes
        H5Pset_obj_track_times(untimed.get(), 0);
        Handle g(H5Gcreate2(id(), prefix.c_str(), H5P_DEFAULT, untimed.get(), H5P_DEFAULT), H5Gclose);
        if (!g.valid()) fail_at(name_, prefix, "cannot create the group");
      }
      if (end == std::string::npos) break;
      at = end + 1;
    }
  }

  bool exists(const std::string& path) const {
    ScopedSilence silence;
    // Every prefix must exist for H5Lexists to answer about the last link.
    std::size_t at = 1;
    while (true) {
      const std::size_t end = path.find('/', at);
      if (H5Lexists(id(), path.substr(0, end).c_str(), H5P_DEFAULT) <= 0) return false;
      if (end == std::string::npos) return true;
      at = end + 1;
    }
  }

  /// Writes a row-major array of `shape` (a new dataset). When compression > 0: gzip at that
  /// level (1-9), `chunk_rows` rows of the first dimension per chunk (1 for images: reading frame t
  /// decompresses frame t only), and with `shuffle` HDF5's byte shuffle first (the bytes of equal
  /// significance of neighbouring numbers side by side: smooth float64 series compress far
  /// better). Both filters are built into HDF5 and h5py.
  template <typename T>
  void write(const std::string& path, const std::vector<hsize_t>& shape, const T* values, int compression = 0,
             hsize_t chunk_rows = 1, bool shuffle = false) {
    ScopedSilence silence;
    Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose);
    Handle properties(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_obj_track_times(properties.get(), 0);  // no modification times: same content, same bytes
    bool empty = false;
    for (hsize_t s : shape) empty = empty || s == 0;
    if (compression > 0 && !empty) {
      std::vector<hsize_t> chunk = shape;
      chunk[0] = std::clamp<hsize_t>(chunk_rows, 1, shape[0]);
      H5Pset_chunk(properties.get(), static_cast<int>(chunk.size()), chunk.data());
      if (shuffle) H5Pset_shuffle(properties.get());
      H5Pset_deflate(properties.get(), static_cast<unsigned>(compression));
    }
    Handle data(H5Dcreate2(id(), path.c_str(), native_type<T>(), space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                H5Dclose);
    if (!data.valid()) fail_at(name_, path, "cannot create the dataset (does it exist already?)");
    if (!empty && H5Dwrite(data.get(), native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0)
      fail_at(name_, path, "writing the dataset failed");
  }

  /// The shape of the dataset at `path`.
  std::vector<hsize_t> shape(const std::string& path) const {
    ScopedSilence silence;
    return dims_of(open_dataset(path), path);
  }

  /// The stored element type of the dataset at `path`: "float64", "float32", "uint8", "int64",
  /// "string", or a description of any other type ("integer of 2 bytes, signed").
  std::string dtype(const std::string& path) const {
    ScopedSilence silence;
    const Handle data = open_dataset(path);
    Handle stored(H5Dget_type(data.get()), H5Tclose);
    const H5T_class_t kind = H5Tget_class(stored.get());
    const std::size_t size = H5Tget_size(stored.get());
    if (kind == H5T_FLOAT && (size == 8 || size == 4)) return size == 8 ? "float64" : "float32";
    if (kind == H5T_STRING) return "string";
    if (kind == H5T_INTEGER) {
      const bool is_signed = H5Tget_sign(stored.get()) == H5T_SGN_2;
      if (size == 1 && !is_signed) return "uint8";
      if (size == 8 && is_signed) return "int64";
      return "integer of " + std::to_string(size) + " bytes, " + (is_signed ? "signed" : "unsigned");
    }
    return "type class " + std::to_string(static_cast<int>(kind)) + " of " + std::to_string(size) + " bytes";
  }

  /// Reads a whole dataset as T (converted by HDF5 from the stored type); `shape` gets its shape.
  template <typename T>
  std::vector<T> read(const std::string& path, std::vector<hsize_t>& shape) const {
    ScopedSilence silence;
    const Handle data = open_dataset(path);
    shape = dims_of(data, path);
    std::vector<T> values(stored_count(data, path, shape));
    if (!values.empty() && H5Dread(data.get(), native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
      fail_at(name_, path, "reading the dataset failed (truncated or corrupted file?)");
    return values;
  }

  /// A variable-length UTF-8 string attribute on the object at `path` ("/" for the file).
  void write_attribute(const std::string& path, const std::string& name, const std::string& value) {
    ScopedSilence silence;
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(type.get(), H5T_VARIABLE);
    H5Tset_cset(type.get(), H5T_CSET_UTF8);
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attribute(H5Acreate_by_name(id(), path.c_str(), name.c_str(), type.get(), space.get(), H5P_DEFAULT,
                                       H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose);
    if (!attribute.valid()) fail_at(name_, path, "cannot create attribute '", name, "'");
    const char* text = value.c_str();
    if (H5Awrite(attribute.get(), type.get(), &text) < 0) fail_at(name_, path, "writing attribute '", name, "' failed");
  }

  /// A scalar numeric attribute (int64 or double).
  template <typename T>
  void write_attribute(const std::string& path, const std::string& name, T value)
    requires std::is_arithmetic_v<T>
  {
    ScopedSilence silence;
    using Stored = std::conditional_t<std::is_floating_point_v<T>, double, std::int64_t>;
    const Stored stored = static_cast<Stored>(value);
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attribute(H5Acreate_by_name(id(), path.c_str(), name.c_str(), native_type<Stored>(), space.get(),
                                       H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose);
    if (!attribute.valid()) fail_at(name_, path, "cannot create attribute '", name, "'");
    if (H5Awrite(attribute.get(), native_type<Stored>(), &stored) < 0) fail_at(name_, path, "writing attribute '", name, "' failed");
  }

  std::string read_string_attribute(const std::string& path, const std::string& name) const {
    ScopedSilence silence;
    Handle attribute = open_attribute(path, name);
    Handle stored(H5Aget_type(attribute.get()), H5Tclose);
    if (H5Tget_class(stored.get()) != H5T_STRING) fail_at(name_, path, "attribute '", name, "' is not a string");
    Handle space(H5Aget_space(attribute.get()), H5Sclose);
    if (H5Tis_variable_str(stored.get()) > 0) {
      Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(type.get(), H5T_VARIABLE);
      H5Tset_cset(type.get(), H5Tget_cset(stored.get()));
      char* text = nullptr;
      if (H5Aread(attribute.get(), type.get(), &text) < 0) fail_at(name_, path, "reading attribute '", name, "' failed");
      std::string value = text != nullptr ? text : "";
      H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, &text);
      return value;
    }
    const std::size_t size = H5Tget_size(stored.get());
    std::string value(size, '\0');
    if (H5Aread(attribute.get(), stored.get(), value.data()) < 0) fail_at(name_, path, "reading attribute '", name, "' failed");
    return value.substr(0, value.find('\0'));
  }

  template <typename T>
  T read_numeric_attribute(const std::string& path, const std::string& name) const {
    ScopedSilence silence;
    Handle attribute = open_attribute(path, name);
    T value{};
    if (H5Aread(attribute.get(), native_type<T>(), &value) < 0)
      fail_at(name_, path, "attribute '", name, "' is not a number");
    return value;
  }

  /// Names of the links in the group at `path`, in name order.
  std::vector<std::string> children(const std::string& path) const {
    ScopedSilence silence;
    Handle group(H5Gopen2(id(), path.c_str(), H5P_DEFAULT), H5Gclose);
    if (!group.valid()) fail_at(name_, path, "missing group");
    H5G_info_t info;
    if (H5Gget_info(group.get(), &info) < 0) fail_at(name_, path, "unreadable group");
    std::vector<std::string> names;
    for (hsize_t i = 0; i < info.nlinks; ++i) names.push_back(indexed_name(group.get(), path, i, false));
    return names;
  }

  /// Names of the attributes of the object at `path`, in name order.
  std::vector<std::string> attribute_names(const std::string& path) const {
    ScopedSilence silence;
    Handle object(H5Oopen(id(), path.c_str(), H5P_DEFAULT), H5Oclose);
    if (!object.valid()) fail_at(name_, path, "missing object");
    const int count = H5Aget_num_attrs(object.get());
    std::vector<std::string> names;
    for (int i = 0; i < count; ++i) names.push_back(indexed_name(object.get(), path, static_cast<hsize_t>(i), true));
    return names;
  }

  bool attribute_is_string(const std::string& path, const std::string& name) const {
    ScopedSilence silence;
    Handle attribute = open_attribute(path, name);
    Handle stored(H5Aget_type(attribute.get()), H5Tclose);
    return H5Tget_class(stored.get()) == H5T_STRING;
  }

  /// A soft link to an object in another file (HDF5 external link; h5py follows it).
  void link_external(const std::string& path, const std::string& target_file, const std::string& target_path) {
    ScopedSilence silence;
    if (H5Lcreate_external(target_file.c_str(), target_path.c_str(), id(), path.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0)
      fail_at(name_, path, "cannot create the external link to ", target_file, ":", target_path);
  }

  /// A 1-D dataset of fixed-length byte strings (robomimic's mask/<split> convention).
  void write_strings(const std::string& path, const std::vector<std::string>& values) {
    ScopedSilence silence;
    std::size_t width = 1;
    for (const auto& v : values) width = std::max(width, v.size());
    std::vector<char> packed(values.size() * width, '\0');
    for (std::size_t i = 0; i < values.size(); ++i) values[i].copy(packed.data() + i * width, values[i].size());
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(type.get(), width);
    H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
    const hsize_t n = values.size();
    Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
    Handle untimed(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_obj_track_times(untimed.get(), 0);
    Handle data(H5Dcreate2(id(), path.c_str(), type.get(), space.get(), H5P_DEFAULT, untimed.get(), H5P_DEFAULT), H5Dclose);
    if (!data.valid()) fail_at(name_, path, "cannot create the string dataset");
    if (n > 0 && H5Dwrite(data.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, packed.data()) < 0)
      fail_at(name_, path, "writing the string dataset failed");
  }

  std::vector<std::string> read_strings(const std::string& path) const {
    ScopedSilence silence;
    if (!exists(path)) fail_at(name_, path, "missing dataset");
    Handle data(H5Dopen2(id(), path.c_str(), H5P_DEFAULT), H5Dclose);
    Handle stored(H5Dget_type(data.get()), H5Tclose);
    if (H5Tget_class(stored.get()) != H5T_STRING || H5Tis_variable_str(stored.get()) > 0)
      fail_at(name_, path, "expected fixed-length strings");
    const std::size_t width = H5Tget_size(stored.get());
    Handle space(H5Dget_space(data.get()), H5Sclose);
    hsize_t n = 0;
    H5Sget_simple_extent_dims(space.get(), &n, nullptr);
    n = stored_count(data, path, {n});
    std::vector<char> packed(n * width + 1, '\0');
    if (n > 0 && H5Dread(data.get(), stored.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, packed.data()) < 0)
      fail_at(name_, path, "reading the string dataset failed");
    std::vector<std::string> values;
    for (hsize_t i = 0; i < n; ++i) {
      std::string v(packed.data() + i * width, width);
      values.push_back(v.substr(0, v.find('\0')));
    }
    return values;
  }

 private:
  File(std::string name, Handle handle) : name_(std::move(name)), handle_(std::move(handle)) {}

  Handle open_attribute(const std::string& path, const std::string& name) const {
    if (!exists(path) && path != "/") fail_at(name_, path, "missing object");
    if (H5Aexists_by_name(id(), path.c_str(), name.c_str(), H5P_DEFAULT) <= 0) fail_at(name_, path, "missing attribute '", name, "'");
    Handle attribute(H5Aopen_by_name(id(), path.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (!attribute.valid()) fail_at(name_, path, "cannot open attribute '", name, "'");
    return attribute;
  }

  Handle open_dataset(const std::string& path) const {
    if (!exists(path)) fail_at(name_, path, "missing dataset");
    Handle data(H5Dopen2(id(), path.c_str(), H5P_DEFAULT), H5Dclose);
    if (!data.valid()) fail_at(name_, path, "cannot open the dataset (not a dataset, or the file is damaged)");
    return data;
  }

  /// The number of values of the dataset of `shape`, refused when the file cannot hold them: a
  /// header of a few bytes can declare 2^40 rows whose chunks were never written (reading them
  /// would allocate terabytes). Allowed: at most 1032 bytes of values per byte stored for the
  /// dataset (deflate's largest ratio; unfiltered data is stored 1:1).
  std::size_t stored_count(const Handle& data, const std::string& path, const std::vector<hsize_t>& shape) const {
    Handle stored(H5Dget_type(data.get()), H5Tclose);
    const hsize_t width = std::max<hsize_t>(1, H5Tget_size(stored.get()));
    const hsize_t bytes_stored = H5Dget_storage_size(data.get());
    constexpr hsize_t max_ratio = 1032;
    const hsize_t limit = std::min<hsize_t>(bytes_stored, std::numeric_limits<hsize_t>::max() / max_ratio) * max_ratio / width;
    hsize_t count = 1;
    for (hsize_t n : shape) {
      if (n != 0 && count > limit / n) {
        std::string dims;
        for (hsize_t d : shape) dims += (dims.empty() ? "" : " x ") + std::to_string(d);
        fail_at(name_, path, "a dataset of ", dims, " values of ", width, " bytes has only ", bytes_stored,
                " bytes stored (truncated or corrupted file?)");
      }
      count *= n;
    }
    return static_cast<std::size_t>(count);
  }

  std::vector<hsize_t> dims_of(const Handle& data, const std::string& path) const {
    Handle space(H5Dget_space(data.get()), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) fail_at(name_, path, "unreadable dataspace");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank), 0);
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    return dims;
  }

  std::string indexed_name(hid_t location, const std::string& path, hsize_t i, bool attribute) const {
    const auto query = [&](char* buffer, std::size_t size) {
      return attribute ? H5Aget_name_by_idx(location, ".", H5_INDEX_NAME, H5_ITER_INC, i, buffer, size, H5P_DEFAULT)
                       : H5Lget_name_by_idx(location, ".", H5_INDEX_NAME, H5_ITER_INC, i, buffer, size, H5P_DEFAULT);
    };
    const ssize_t length = query(nullptr, 0);
    if (length < 0) fail_at(name_, path, "unreadable member name");
    std::string text(static_cast<std::size_t>(length) + 1, '\0');
    query(text.data(), text.size());
    text.resize(static_cast<std::size_t>(length));
    return text;
  }

  std::string name_;
  Handle handle_;
};

}  // namespace manisoft::dataset::h5
