"""What several test modules share: worksheet texts, builders and comparisons (a test
module imports from here, never from another test module)."""
