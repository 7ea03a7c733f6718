#include "iblkit/core/enum_names.h"

#include <gtest/gtest.h>

namespace ibl {
namespace {

enum class Fruit { Apple, Pear, Plum };
constexpr EnumName<Fruit> kFruitNames[] = {
    {Fruit::Apple, "apple"}, {Fruit::Pear, "pear"}, {Fruit::Plum, "plum"}, {Fruit::Apple, "malus"}};

TEST(EnumNames, NamesAliasesAndRoundTrip) {
  static_assert(name_of(kFruitNames, Fruit::Pear)[0] == 'p');  // usable at compile time
  for (Fruit f : {Fruit::Apple, Fruit::Pear, Fruit::Plum})
    EXPECT_EQ(parse_enum(kFruitNames, name_of(kFruitNames, f), "fruit"), f);
  EXPECT_STREQ(name_of(kFruitNames, Fruit::Apple), "apple");  // the first entry, not the alias
  EXPECT_EQ(find_enum(kFruitNames, "malus"), Fruit::Apple);
  EXPECT_EQ(find_enum(kFruitNames, "Apple"), std::nullopt);  // exact: callers fold case themselves
  EXPECT_STREQ(name_of(kFruitNames, static_cast<Fruit>(7)), "?");
  EXPECT_EQ(enum_names(kFruitNames), "apple, pear or plum");
}

TEST(EnumNames, UnknownNameListsTheValidOnes) {
  try {
    parse_enum(kFruitNames, "kiwi", "fruit", "--fruit");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Value);
    EXPECT_STREQ(e.what(), "--fruit: unknown fruit 'kiwi' (use apple, pear or plum)");
  }
  try {
    parse_enum(kFruitNames, "", "fruit");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "unknown fruit '' (use apple, pear or plum)");
  }
}

}  // namespace
}  // namespace ibl
