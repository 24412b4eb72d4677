// The CPU reference (filled in next).
