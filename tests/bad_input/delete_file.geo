// Included by include_delete.geo.
DeleteFile "knee_contact_was_here";
