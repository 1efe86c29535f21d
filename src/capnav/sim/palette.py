"""Named colours and materials: the attribute vocabulary that makes lookalike instances differ."""

from __future__ import annotations

COLORS: dict[str, tuple[int, int, int]] = {
    "red": (178, 34, 34),
    "blue": (40, 70, 170),
    "navy": (25, 35, 90),
    "light blue": (120, 170, 220),
    "green": (46, 120, 60),
    "olive": (110, 110, 40),
    "teal": (20, 120, 120),
    "yellow": (225, 190, 40),
    "mustard": (200, 150, 30),
    "orange": (220, 110, 30),
    "pink": (225, 130, 160),
    "purple": (110, 50, 140),
    "white": (235, 235, 230),
    "cream": (235, 225, 195),
    "beige": (205, 185, 150),
    "grey": (128, 128, 128),
    "light grey": (185, 185, 185),
    "dark grey": (70, 70, 72),
    "black": (28, 28, 30),
    "brown": (110, 70, 40),
    "dark brown": (70, 45, 28),
    "tan": (190, 150, 100),
    "oak": (180, 140, 90),
    "walnut": (95, 65, 45),
    "silver": (190, 192, 196),
    "terracotta": (190, 95, 60),
}

UPHOLSTERY = ["red", "blue", "navy", "light blue", "green", "olive", "teal", "yellow", "mustard", "orange",
              "pink", "purple", "white", "cream", "beige", "grey", "light grey", "dark grey", "black", "brown"]
WOODS = ["oak", "walnut", "brown", "dark brown", "tan", "white", "black", "grey"]
APPLIANCE = ["white", "silver", "black", "dark grey"]
SANITARY = ["white", "cream", "light grey", "black"]
POTS = ["terracotta", "white", "black", "grey", "blue", "green", "yellow"]

# Per-category (colour choices, material choices) of the instance's main colour.
CATEGORY_STYLE: dict[str, tuple[list[str], list[str]]] = {
    "sofa": (UPHOLSTERY, ["fabric", "leather", "velvet"]),
    "armchair": (UPHOLSTERY, ["fabric", "leather", "velvet"]),
    "chair": (UPHOLSTERY + WOODS, ["wood", "plastic", "fabric", "metal"]),
    "stool": ([*WOODS, "red", "blue", "yellow", "silver"], ["wood", "metal", "plastic"]),
    "table": (WOODS, ["wood", "glass", "marble"]),
    "coffee table": ([*WOODS, "white", "black"], ["wood", "glass", "marble"]),
    "desk": (WOODS, ["wood", "metal", "laminate"]),
    "bed": (UPHOLSTERY, ["fabric", "velvet", "cotton"]),
    "nightstand": (WOODS, ["wood", "laminate"]),
    "wardrobe": (WOODS, ["wood", "laminate"]),
    "dresser": ([*WOODS, "blue", "green", "pink"], ["wood", "laminate"]),
    "cabinet": ([*WOODS, "blue", "green", "red", "yellow"], ["wood", "laminate", "metal"]),
    "bookshelf": (WOODS, ["wood", "metal"]),
    "tv": (["black", "dark grey", "silver", "white"], ["plastic", "metal"]),
    "lamp": (["white", "cream", "black", "red", "yellow", "blue", "green", "orange"], ["fabric", "paper", "metal"]),
    "plant": (POTS, ["ceramic", "terracotta", "plastic"]),
    "toilet": (SANITARY, ["ceramic"]),
    "sink": (SANITARY, ["ceramic", "marble"]),
    "bathtub": (SANITARY, ["ceramic", "acrylic"]),
    "refrigerator": ([*APPLIANCE, "red", "light blue", "cream"], ["metal", "stainless steel"]),
    "counter": ([*WOODS, "white", "grey", "navy", "green"], ["wood", "laminate", "marble"]),
    "stove": (APPLIANCE, ["metal", "stainless steel"]),
    "washing machine": (APPLIANCE, ["metal", "plastic"]),
    "ottoman": (UPHOLSTERY, ["fabric", "leather", "velvet"]),
}

# Secondary colour roles, fixed per material family (legs, metal fittings, glass tops, foliage).
ROLE_COLORS: dict[str, tuple[int, int, int]] = {
    "metal": (170, 172, 176),
    "dark": (35, 35, 38),
    "white": (240, 240, 236),
    "glass": (170, 200, 210),
    "leaf": (50, 125, 45),
    "leaf2": (80, 150, 60),
    "soil": (70, 50, 35),
    "screen": (15, 15, 22),
    "mattress": (238, 238, 232),
    "pillow": (245, 245, 245),
    "shade": (245, 235, 210),
}

BOOK_COLORS: list[tuple[int, int, int]] = [(150, 30, 30), (30, 60, 130), (200, 170, 60), (40, 110, 60),
                                           (220, 220, 210), (90, 40, 100), (30, 30, 30), (200, 90, 40)]

ROOM_FLOORS: dict[str, list[tuple[str, tuple[int, int, int]]]] = {
    "living room": [("parquet", (170, 125, 80)), ("parquet", (140, 100, 65)), ("carpet", (150, 140, 120))],
    "kitchen": [("tiles", (200, 200, 195)), ("tiles", (170, 160, 150)), ("tiles", (120, 120, 125))],
    "bedroom": [("carpet", (170, 160, 140)), ("parquet", (180, 140, 95)), ("carpet", (120, 130, 150))],
    "bathroom": [("tiles", (225, 225, 225)), ("tiles", (90, 110, 130)), ("tiles", (180, 190, 185))],
    "office": [("parquet", (160, 120, 80)), ("carpet", (110, 110, 115))],
    "hallway": [("parquet", (150, 110, 70)), ("tiles", (160, 150, 140))],
}

ROOM_WALLS: list[tuple[int, int, int]] = [(228, 225, 215), (215, 220, 225), (230, 220, 200), (205, 215, 200),
                                          (235, 235, 232), (220, 205, 200), (200, 210, 225)]
CEILING: tuple[int, int, int] = (245, 245, 242)
