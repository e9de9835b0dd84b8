// The harm is in an included file.
Include "delete_file.geo";
