// AtomicFileTest — the one file writer (server/io/atomic_file): whole files or none, no temporary
// left behind, links replaced rather than followed, failures that leave the target as it was;
// whole-file reads with a size limit. Files only.
#include "io/atomic_file.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <filesystem>

using namespace dermis;
using namespace dermis::test;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes(const std::string& s) { return {s.begin(), s.end()}; }

/// Names in `folder` for which isTempName holds.
std::vector<std::string> tempNames(const std::string& folder) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(folder))
        if (isTempName(e.path().filename().string())) out.push_back(e.path().filename().string());
    return out;
}

TEST(AtomicFileTest, WritesReplaceWholeFilesInBothDurabilities) {
    TempDir dir;
    const std::string path = dir / "f.txt";
    for (Durability d : {Durability::Atomic, Durability::Durable}) {
        ASSERT_TRUE(writeFileAtomically(path, bytes("first version, long"), d));
        EXPECT_EQ(readBytes(path), bytes("first version, long"));
        ASSERT_TRUE(writeFileAtomically(path, bytes("second"), d));
        EXPECT_EQ(readBytes(path), bytes("second"));
        ASSERT_TRUE(writeFileAtomically(path, {}, d));
        EXPECT_TRUE(readBytes(path).empty());
    }
    EXPECT_TRUE(tempNames(dir.str()).empty());
}

TEST(AtomicFileTest, FailuresNameTheTargetAndLeaveItAsItWas) {
    TempDir dir;
    auto missing = writeFileAtomically(dir / "no/such/folder/f.txt", bytes("x"),
                                       Durability::Durable, "dermis::caller");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::Io);
    EXPECT_EQ(missing.error().field, dir / "no/such/folder/f.txt");
    EXPECT_NE(missing.error().message.find("dermis::caller"), std::string::npos);

    // A folder at the target: the rename fails, the folder and its content stay, no temp file.
    fs::create_directories(dir / "target");
    writeText(dir / "target/inside.txt", "kept");
    auto onFolder = writeFileAtomically(dir / "target", bytes("x"));
    ASSERT_FALSE(onFolder);
    EXPECT_EQ(onFolder.error().code, ErrorCode::Io);
    EXPECT_EQ(readBytes(dir / "target/inside.txt"), bytes("kept"));
    EXPECT_TRUE(tempNames(dir.str()).empty());
}

TEST(AtomicFileTest, ALinkAtTheTargetIsReplacedNotFollowed) {
    TempDir dir;
    writeText(dir / "elsewhere.txt", "untouched");
    fs::create_symlink(dir / "elsewhere.txt", dir / "link.txt");
    ASSERT_TRUE(writeFileAtomically(dir / "link.txt", bytes("new")));
    EXPECT_FALSE(fs::is_symlink(dir / "link.txt"));
    EXPECT_EQ(readBytes(dir / "link.txt"), bytes("new"));
    EXPECT_EQ(readBytes(dir / "elsewhere.txt"), bytes("untouched"));
}

TEST(AtomicFileTest, TempNamesAreRecognisedByTheirMarker) {
    EXPECT_TRUE(isTempName("s_1.json.tmp.123.0"));
    EXPECT_TRUE(isTempName("m_1.d.tmp.42"));
    EXPECT_TRUE(isTempName(std::string("x") + kTempMarker + "1"));
    EXPECT_FALSE(isTempName("s_1.json"));
    EXPECT_FALSE(isTempName("template.png"));
    EXPECT_FALSE(isTempName("tmp.png"));
}

TEST(AtomicFileTest, WholeFileReadsKnowMissingFoldersAndLimits) {
    TempDir dir;
    writeText(dir / "f.bin", "0123456789");
    auto all = readWholeFile(dir / "f.bin");
    ASSERT_TRUE(all);
    EXPECT_EQ(*all, bytes("0123456789"));
    auto limited = readWholeFile(dir / "f.bin", 9);
    ASSERT_FALSE(limited);
    EXPECT_EQ(limited.error().code, ErrorCode::TooLarge);
    EXPECT_TRUE(readWholeFile(dir / "f.bin", 10));
    auto missing = readWholeFile(dir / "nope.bin");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::NotFound);
    EXPECT_EQ(missing.error().field, dir / "nope.bin");
    auto folder = readWholeFile(dir.str());
    ASSERT_FALSE(folder);
    EXPECT_EQ(folder.error().code, ErrorCode::Io);
}

} // namespace
