// The image's own translation unit: everything is in the board library (main included).
